"""Parameter studies on dask.distributed: many variants of a model, one row of results per run.

    import mbdsim as mb
    study = mb.Study("slider_crank.yaml",
                     parameters={"bodies.rod.mass": {"range": ["1 kg", "3 kg"]},
                                 "bodies.slider.mass": [1.0, 1.5, 2.0]},
                     outputs={"peak_rod_force": "max(norm(reaction_force('crank_rod')))"},
                     analysis={"end_time": 2.0, "output_step": 0.01, "rtol": 1e-6},
                     sampling="lhs", samples=50)
    df = study.run(workers=2, out="results.parquet")     # or client=Client(...) / "tcp://host:8786"
    mb.sensitivity(df, ["bodies.rod.mass", "bodies.slider.mass"], ["peak_rod_force"])
    mb.plot_study(df, kind="main_effects")

Modules: design (parameter specs, samplers), measures (output expressions), variant (one run; the Dask
task), runner (Dask, Parquet, resume), store, spec (study files), sensitivity, plots, models (factories).

Throughput (docs/studies.md, bench/study_throughput.py): kernels compiled once per process and reused by
every variant (a variant's compiled model is its own numeric arrays, from its own assembly); chunks of
variants per Dask task; outputs evaluated on all samples at once, extrema refined with grids of dense-output
times (refine), reactions from one compiled minimum-norm solve (mbdsim.solvers.minnorm) with the Result's
geometry reused; run monitors skipped unless a callable output may read them.  Several parameter sets in
one compiled call would only save the calls' overhead (tens of microseconds against milliseconds of
integration and per-variant assembly), so variants run one after the other inside a chunk.
"""
from .spec import load_study
from .study import Study
from .sensitivity import sensitivity   # eager: a lazy one is shadowed by the submodule once imported

__all__ = ["Study", "load_study", "sensitivity", "plot_study"]


def __getattr__(name):
    if name == "plot_study":
        from .plots import plot_study
        return plot_study
    raise AttributeError(f"module 'mbdsim.studies' has no attribute {name!r}")
