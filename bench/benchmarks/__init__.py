"""The pytest-benchmark suites (``pytest bench --benchmark-only``) and the reference costs they compare
against (:mod:`bench.benchmarks.baselines`)."""
