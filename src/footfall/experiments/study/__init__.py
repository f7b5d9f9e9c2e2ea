"""Section 5.5 studies (``footfall study``): a declared design of scenes x planners x step counts x
push levels x seeds, walked on a local process pool or Ray, stored one row per trial in Parquet
(resumable), summarised with confidence intervals and paired tests.

- :mod:`.design`: :class:`StudyDesign`, the study YAML.
- :mod:`.trials`: one walk as one row (:func:`run_trial`).
- :mod:`.store`: ``trials.parquet`` written as trials finish.
- :mod:`.runner`: plans, trials, executors (:func:`run_study`).
- :mod:`.stats`, :mod:`.report`: the statistics and ``summary.md``.
"""

from footfall.experiments.study.design import (
    BUILTIN_STUDIES,
    StudyDesign,
    builtin_study,
    load_study,
    parse_study,
)
from footfall.experiments.study.report import Summary, summarise, write_report
from footfall.experiments.study.runner import EXECUTORS, StudyRun, run_study
from footfall.experiments.study.trials import COLUMNS, Trial, run_trial

__all__ = [
    "BUILTIN_STUDIES",
    "COLUMNS",
    "EXECUTORS",
    "StudyDesign",
    "StudyRun",
    "Summary",
    "Trial",
    "builtin_study",
    "load_study",
    "parse_study",
    "run_study",
    "run_trial",
    "summarise",
    "write_report",
]
