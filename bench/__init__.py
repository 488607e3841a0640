"""pytest-benchmark suites, their baselines and (later) Monte Carlo studies."""
