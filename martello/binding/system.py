"""The one call to the operating system that the standard library lacks: a process that dies
with its parent (the pool workers of a sweep, martello.batch).

Linux's prctl(PR_SET_PDEATHSIG) has the kernel send a signal to a process when the thread
that created it ends (prctl(2)); elsewhere, or if the call fails, a watchdog thread polls
getppid(), which changes when the parent dies and the process is re-parented (to init or a
subreaper)."""

import ctypes
import os
import signal
import threading
import time

PR_SET_PDEATHSIG = 1            # <linux/prctl.h>
WATCH_S = 0.5                   # the watchdog's period: a parent's death is noticed within it


def die_with_parent(parent):
    """Make this process end (SIGKILL, or os._exit(1) from the watchdog) when the process
    `parent` — its parent when it started — ends, however it ends (SIGKILL, the out-of-memory
    killer, a crash). Call it first thing in the child."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
    except (OSError, AttributeError):       # no prctl (not Linux): the watchdog alone
        pass
    if os.getppid() != parent:              # it ended before the call took effect
        os._exit(1)

    def watch():
        while os.getppid() == parent:
            time.sleep(WATCH_S)
        os._exit(1)

    threading.Thread(target=watch, name="martello-parent-watchdog", daemon=True).start()
