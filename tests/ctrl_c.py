"""The command line as a child process that a test interrupts as a terminal's Ctrl-C would."""

import sys

#: ``python -m driver.cli`` with SIGINT at Python's own handler, whatever the test runner's. A runner started in
#: the background (``make test &``, under nohup, by some CI agents) has SIGINT ignored, its children inherit that,
#: and Python then installs no KeyboardInterrupt: the signal a test sends would be lost, and the test would wait
#: out its deadline and fail.
CLI = [
    sys.executable,
    "-c",
    "import runpy, signal; signal.signal(signal.SIGINT, signal.default_int_handler); "
    "runpy.run_module('driver.cli', run_name='__main__', alter_sys=True)",
]
