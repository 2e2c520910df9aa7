# SPDX-License-Identifier: Apache-2.0
"""A closed-loop run as the tools write it (docs/tools.md, "A faulted run is not
a result"): the one place the studies ask whether a run faulted and say how;
and the one way a study runs a step that must succeed."""


def faulted(run_):
    """the firmware stopped the axis: the run ended early, its figures are null, no result"""
    return run_.get("fault_status", 0) != 0


def fault_text(run_):
    """the fault where a figure would stand: its time and cause"""
    return "fault at %.3f s (%s)" % (run_["fault_t_s"], run_.get("fault_cause", "unknown"))


def run_or_exit(tool, cmd, **kw):
    """subprocess.run(cmd) after printing it; a failure ends the study (exit 1, naming tool)."""
    import subprocess
    import sys
    print("$ " + " ".join(cmd), flush=True)
    r = subprocess.run(cmd, **kw)
    if r.returncode != 0:
        sys.exit("%s: failed (exit %d): %s" % (tool, r.returncode, " ".join(cmd)))
    return r
