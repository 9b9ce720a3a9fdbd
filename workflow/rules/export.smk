# ParaView output: a run's stored states as VTK files (isaflow.export: <run>.pvd, one .vtu of particles per stored
# state, the walls' .vtp with each panel's load and the run's at-rest and wall numbers) in results/vtk/<method>/<run>/.
# Target `vtk` (snakemake -c2 vtk): the flows of every method, i.e. each run a tank method marks 'compare: true'
# on a tank of two or more vessels.  Not part of the full run: a flow is 50-230 files of 20-60 kB each.


use rule call as export_vtk with:
    input:
        runs=lambda wc: run_file(wc.method, wc.run),
        code=code("export"),
    output:
        "results/vtk/{method}/{run}/{run}.pvd",
    params:
        func="export.export_runs",
    log:
        "logs/vtk/{method}/{run}.log",
    wildcard_constraints:
        method="|".join(TANK_METHODS),


rule vtk:
    input:
        lambda wc: [vtk_file(m, r) for m, r in flow_runs()],
