# SPDX-License-Identifier: Apache-2.0
"""A closed-loop run as the tools write it (docs/tools.md, "A faulted run is not
a result"): the one place the studies ask whether a run faulted and say how."""


def faulted(run_):
    """the firmware stopped the axis: the run ended early, its figures are null, no result"""
    return run_.get("fault_status", 0) != 0


def fault_text(run_):
    """the fault where a figure would stand: its time and cause"""
    return "fault at %.3f s (%s)" % (run_["fault_t_s"], run_.get("fault_cause", "unknown"))
