"""A flow as an animation (GIF), from run files only: the stored states (snap_*, driver.drive) of a chain of runs.

One frame per stored state (at most MAX_FRAMES of them, spaced evenly along the liquid's motion: :func:`pick`),
in chain order (a run that continues another repeats its last state as its first: shown once): the particles coloured by their speed
(a method with velocities) or by their out-of-balance force |F| (ISA; grey where not known: before the
run's first evaluation), on one colour scale for the whole animation (up to the 99th percentile of every
frame's values), the walls, and the time after the flow's
opening (s, or steps for a method without a clock) with the share of the liquid's weight in each vessel.
Written with matplotlib's PillowWriter.  Units cm, N, s.
"""

from pathlib import Path

import numpy as np

from .. import at_rest, runfile
from .style import draw_walls, plt

MAX_FRAMES = 60  # frames of a GIF (size: 20-50 kB each at this resolution)
FPS = 6  # frames per second: 60 frames play in 10 s


def _frames(dss):
    """[(clock, pos (N, 2), colour value (N,))] of the stored states of a chain of runs, each state once, and the
    colour's name and units."""
    out, last = [], None
    for ds in dss:
        if "snap_pos" not in ds:
            raise ValueError(f"run {ds.attrs.get('run_id')}: no stored states (snap_pos) to animate")
        clocks = ds["snap_time"].values if "snap_time" in ds else ds["snap_step"].values
        if "snap_velocity" in ds:
            values, what = np.hypot(*np.moveaxis(ds["snap_velocity"].values.astype(float), -1, 0)), "speed (cm/s)"
        else:
            values, what = np.hypot(*np.moveaxis(ds["snap_force"].values.astype(float), -1, 0)), "|F| (N)"
        for c, pos, v in zip(clocks, ds["snap_pos"].values, values):
            if last is not None and c == last:
                continue
            out.append((float(c), pos, v))
            last = c
    return out, what


def pick(frames, n):
    """Indices of at most n frames, the first and the last among them, evenly spaced along the liquid's motion and
    its stored states together (the cumulative rms displacement between stored states, as a fraction of its total,
    plus the state's index as a fraction of theirs): a drain of 2 s gets most frames, a long stretch at rest
    after it some."""
    if len(frames) <= n:
        return list(range(len(frames)))
    moved = np.concatenate([[0.0], np.cumsum([np.sqrt(np.mean(np.sum((b[1] - a[1]) ** 2, axis=1)))
                                              for a, b in zip(frames, frames[1:])])])
    along = np.linspace(0.0, 1.0, len(frames)) + (moved / moved[-1] if moved[-1] > 0 else 0.0)
    return list(np.unique(np.searchsorted(along, np.linspace(0.0, along[-1], n)).clip(0, len(frames) - 1)))


def flow_animation(runs, outputs, max_frames=MAX_FRAMES, fps=FPS):
    """outputs[0]: the GIF of the flow of ``runs`` (run files of one chain, in order; module docstring)."""
    from matplotlib.animation import FuncAnimation, PillowWriter

    dss = [runfile.read(p) for p in runs]
    frames, what = _frames(dss)
    frames = [frames[k] for k in pick(frames, max_frames)]
    ds = dss[-1]
    timed = "snap_time" in ds
    origin = float(dss[0].attrs.get("start_time", 0.0)) if timed else float(dss[0]["start_step"])
    weight = ds["weight"].values
    vessels = [(str(n), tuple(x)) for n, x in zip(ds["vessel"].values, ds["vessel_x"].values)] \
        if "vessel_x" in ds else [("vessel", (float(ds["wall_segment"].values[:, [0, 2]].min()),
                                              float(ds["wall_segment"].values[:, [0, 2]].max())))]
    vmax = float(np.nanpercentile(np.concatenate([v for _, _, v in frames]), 99)) or 1.0
    walls = ds["wall_segment"].values
    x0, x1 = walls[:, [0, 2]].min(), walls[:, [0, 2]].max()
    y0, y1 = walls[:, [1, 3]].min(), walls[:, [1, 3]].max()
    fig, ax = plt.subplots(figsize=(8.0, 3.6), dpi=72)
    draw_walls(ax, ds)
    pos0 = frames[0][1]
    cmap = plt.get_cmap("viridis").with_extremes(bad="lightgray")  # a value not known at that state (NaN)
    dots = ax.scatter(pos0[:, 0], pos0[:, 1], c=frames[0][2], s=max(2.0, 3000.0 / len(pos0)), cmap=cmap,
                      vmin=0.0, vmax=vmax, plotnonfinite=True)
    fig.colorbar(dots, ax=ax, label=what, shrink=0.8)
    ax.set(aspect="equal", xlim=(x0 - 5, x1 + 5), ylim=(y0 - 5, y1 + 5), xlabel="x (cm)", ylabel="y (cm)")
    title = ax.set_title("")
    fig.suptitle(f"{ds.attrs['method'].upper()} ({ds.attrs['variant']}): {' + '.join(d.attrs.get('run_id', '') for d in dss)}, "
                 f"tank {ds.attrs['tank']}, {len(pos0)} particles", fontsize=9)

    def draw(k):
        c, pos, v = frames[k]
        dots.set_offsets(pos)
        dots.set_array(v)
        share = [float(weight[at_rest.vessel_of(pos, vessels) == i].sum() / weight.sum()) for i in range(len(vessels))]
        when = f"t = {c - origin:.2f} s after the opening" if timed else f"step {int(c):,} ({int(c - origin):,} after the opening)"
        title.set_text(f"{when}; weight in " + ", ".join(f"{n}: {s:.0%}" for (n, _), s in zip(vessels, share)))
        return dots, title

    anim = FuncAnimation(fig, draw, frames=len(frames), blit=False)
    Path(outputs[0]).parent.mkdir(parents=True, exist_ok=True)
    anim.save(outputs[0], writer=PillowWriter(fps=fps))
    plt.close(fig)
    return len(frames)


def report_line(gif, what):
    """The Markdown that shows an animation on a report page (docs/replication.md: figures/ is ../figures/)."""
    return (f"Animation of {what} (its run files' stored states, figures.animation): ![{what}](../{gif})")


def frame_sheet(gif, out, columns=4, rows=3):
    """A PNG of columns x rows frames of a GIF taken evenly (to look at an animation as one picture)."""
    from PIL import Image, ImageSequence

    with Image.open(gif) as im:
        frames = [f.convert("RGB") for f in ImageSequence.Iterator(im)]
    pick = np.unique(np.linspace(0, len(frames) - 1, min(columns * rows, len(frames))).round().astype(int))
    w, h = frames[0].size
    sheet = Image.new("RGB", (w * columns, h * rows), "white")
    for i, k in enumerate(pick):
        sheet.paste(frames[k], ((i % columns) * w, (i // columns) * h))
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    sheet.save(out)
    return len(frames)
