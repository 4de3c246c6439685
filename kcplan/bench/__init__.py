"""Benchmark campaigns against stock OMPL planners (``kcplan bench``).

:mod:`~kcplan.bench.campaign` (run specifications and executors),
:mod:`~kcplan.bench.worker` (one run in a fresh process),
:mod:`~kcplan.bench.ompl_log` (OMPL benchmark logs, Planner Arena database),
:mod:`~kcplan.bench.summary` (per scenario and planner statistics),
:mod:`~kcplan.bench.plots` and :mod:`~kcplan.bench.report` (the output folder).
"""
