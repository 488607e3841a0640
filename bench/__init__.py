"""Monte Carlo studies, their report scripts, the benchmark suites and their baselines (depends on all)."""

from .study import Study, StudyError, load_study

__all__ = ["Study", "StudyError", "load_study"]
