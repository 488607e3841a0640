"""What a run leaves: traces (npz) of both fingers, run logs (JSON lines), the filter's logged calls
and their replay, plots, the part's record that keeps a trace from being scored on another part, and
any of them as an MCAP file.
"""

from .belief_film import FILM_SUFFIXES, MAX_FRAMES, check_film, write_film
from .belief_history import (
    ARC_BINS,
    BeliefHistory,
    finger_outline,
    plot_belief_history,
    replay_beliefs,
    replay_wheel_beliefs,
    sequence_calls,
)
from .filter_log import (
    CALLS,
    FILTER_CALLS_EVENT,
    LOG_COLUMNS,
    REACTIVE_FORMAT,
    LoggedFilter,
    calls_event,
    calls_from_events,
    log_table,
    replay_log,
)
from .mcap_export import READING_PERIOD, SCHEMAS, TOPICS, Message, export_mcap, run_messages, write_mcap
from .part_match import SAME_PART_FLAG, PartMismatch, check_same_part, part_record
from .plotting import draw_part, plot_localization, plot_reactive, plot_run
from .run_record import RECORD_KINDS, RunRecord, check_finger, open_record, reactive_calls
from .runlog import LOG_FORMAT, RunLog, read_log
from .trace import COLUMNS, FORMAT, Trace, read_archive, trace_format
from .wheel_trace import WHEEL_COLUMNS, WHEEL_FORMAT, WheelTrace

__all__ = [
    "FILM_SUFFIXES",
    "MAX_FRAMES",
    "write_film",
    "check_film",
    "ARC_BINS",
    "BeliefHistory",
    "plot_belief_history",
    "replay_beliefs",
    "replay_wheel_beliefs",
    "sequence_calls",
    "finger_outline",
    "CALLS",
    "FILTER_CALLS_EVENT",
    "LOG_COLUMNS",
    "LoggedFilter",
    "REACTIVE_FORMAT",
    "calls_event",
    "calls_from_events",
    "replay_log",
    "log_table",
    "READING_PERIOD",
    "SCHEMAS",
    "TOPICS",
    "Message",
    "export_mcap",
    "run_messages",
    "write_mcap",
    "PartMismatch",
    "SAME_PART_FLAG",
    "check_same_part",
    "part_record",
    "draw_part",
    "plot_localization",
    "plot_reactive",
    "plot_run",
    "RECORD_KINDS",
    "RunRecord",
    "open_record",
    "check_finger",
    "reactive_calls",
    "LOG_FORMAT",
    "RunLog",
    "read_log",
    "COLUMNS",
    "FORMAT",
    "Trace",
    "read_archive",
    "trace_format",
    "WHEEL_COLUMNS",
    "WHEEL_FORMAT",
    "WheelTrace",
]
