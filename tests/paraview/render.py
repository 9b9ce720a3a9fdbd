"""ParaView (pvpython / pvbatch) script: render an isaflow VTK export (isaflow export RUN.nc --vtk DIR).

    pvbatch tests/paraview/render.py RUN.pvd OUT_PREFIX [F ...]

Opens RUN.pvd with ParaView's own PVD reader, shows the particles as points coloured by their speed (|velocity|,
a method with velocities) or |force| (ISA) and the walls as lines coloured by each panel's load, and saves a
picture OUT_PREFIX_<k>.png at each time of the collection a fraction F of the way through its states (default
0, 1/3, 2/3, 1).  Prints one line per picture: its file, the time, the number of particles and the colour
array's range.
"""

import sys

from paraview.simple import (AnnotateTime, ColorBy, ExtractBlock, GetActiveViewOrCreate, GetAnimationScene,
                             GetColorTransferFunction, GetScalarBar, MergeBlocks, PVDReader, Render, ResetCamera,
                             SaveScreenshot, Show)

pvd, prefix = sys.argv[1], sys.argv[2]
fractions = [float(f) for f in sys.argv[3:]] or [0.0, 1 / 3, 2 / 3, 1.0]
reader = PVDReader(FileName=pvd)
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues) if reader.TimestepValues else [0.0]
view = GetActiveViewOrCreate("RenderView")
view.ViewSize = [1200, 560]
view.OrientationAxesVisibility = 0
view.Background = [1.0, 1.0, 1.0]
try:
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass
particles = MergeBlocks(Input=ExtractBlock(Input=reader, Selectors=["/Root/particles"]))
walls = MergeBlocks(Input=ExtractBlock(Input=reader, Selectors=["/Root/walls"]))
pd = Show(particles, view)
pd.SetRepresentationType("Points")
pd.PointSize = 5.0
pd.RenderPointsAsSpheres = 1
names = particles.PointData.keys()
array = "velocity" if "velocity" in names else "force"
ColorBy(pd, ("POINTS", array, "Magnitude"))
pd.SetScalarBarVisibility(view, True)
wd = Show(walls, view)
wd.LineWidth = 4.0
ColorBy(wd, ("CELLS", "load"))
wd.SetScalarBarVisibility(view, True)
BLACK = [0.0, 0.0, 0.0]
for name, title in ((array, "speed (cm/s)" if array == "velocity" else "|F| (N)"), ("load", "panel load (N)")):
    bar = GetScalarBar(GetColorTransferFunction(name), view)
    bar.Title, bar.ComponentTitle, bar.TitleColor, bar.LabelColor = title, "", BLACK, BLACK
clock = AnnotateTime()
clock.Format = ("t = {time:.3f} s" if "velocity" in names else "step {time:.0f}")
label = Show(clock, view)
label.Color, label.FontSize, label.WindowLocation = BLACK, 14, "Upper Left Corner"
view.CameraPosition = [150.0, 25.0, 1000.0]
view.CameraFocalPoint = [150.0, 25.0, 0.0]
view.CameraViewUp = [0.0, 1.0, 0.0]
ResetCamera(view)
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
picks = [times[round(f * (len(times) - 1))] for f in fractions]
lut = GetColorTransferFunction(array)
for k, t in enumerate(picks):
    scene.AnimationTime = t
    view.ViewTime = t
    particles.UpdatePipeline(t)
    info = particles.GetDataInformation()
    rng = particles.PointData[array].GetRange(-1)
    if rng[1] == rng[1] and rng[1] < 1e30:  # a state whose values are not known (NaN: ParaView's NaN colour) keeps the scale
        lut.RescaleTransferFunction(0.0, max(rng[1], 1e-9))
    Render(view)
    out = f"{prefix}_{k}.png"
    SaveScreenshot(out, view, ImageResolution=[1200, 560])
    print(f"{out} time {t:g} particles {info.GetNumberOfPoints()} {array} |.| range {rng[0]:.4g} {rng[1]:.4g}", flush=True)
