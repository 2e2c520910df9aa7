#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""What a board's firmware image runs for a machine file (docs/configure.md,
"The image's estimator"): the estimator (the first of control.estimator the
board can run, the rule of hal/stm32/image/br_image_main.c), its loop period, and its
share of the period from the costs make target-bench measured
(target/mps2/measured_cost.json), and the friction transient over that period
against the reference machine's (docs/fleet.md, "Goals on the fleet": the
strongest predictor of an estimator that stops the axis).

  image_info.py MACHINE.json BOARD      (BOARD: stm32h7 | stm32g4)
Exit 1 (with the reason) when the board runs none of the listed estimators."""
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import machine  # noqa: E402

# what each board's image can run (hal/stm32/image/br_image_main.c) and its core
BOARDS = {"stm32h7": (("pf", "ukf", "none"), "cortex_m7"), "stm32g4": (("ukf", "none"), "cortex_m4")}
COST = os.path.join(HERE, "..", "..", "target", "mps2", "measured_cost.json")
REFERENCE = os.path.join(HERE, "..", "..", "machines", "reference.json")
# the PF's friction transient d = Fc T^2 / (2 Meff) at this many times the reference machine's (its PF at its
# own period) or more: the fleet's highest quartile of d for the PF, where most of its runs stopped the axis
# (docs/fleet.md, "Goals on the fleet"; the UKF's share hardly rises with d there: no warning)
TRANSIENT_WARN_RATIO = 7.0


def image(m, board):
    """(estimator, period_s) of board's image for machine m, or (None, reason)"""
    can, _ = BOARDS[board]
    listed = m["control"]["estimator"].split(",")
    for e in listed:
        if e in can:
            return e, (m["estimator"]["pf"]["period_s"] if e == "pf" else m["control"]["period_s"])
    return None, "control.estimator lists %s; the %s image runs %s" % (",".join(listed), board, ", ".join(can))


def share(m, board, est, period_s):
    """instructions per period and the share of the period, or None where not measured"""
    with open(COST, encoding="utf-8") as f:
        cost = json.load(f)[BOARDS[board][1]]
    if est == "pf" and "pf_fixed_per_period" in cost:
        pf = m["estimator"]["pf"]
        n = cost["pf_per_particle_step"] * pf["n_particles"] + cost["pf_fixed_per_period"]
        if "delay_id" in pf:
            n += cost["pf_delay_id_per_period"]
        return n, n / (cost["mhz"] * 1e6 * period_s)
    if est == "ukf" and "ukf_app_per_period" in cost:
        n = cost["ukf_app_per_period"]
        return n, n / (cost["mhz"] * 1e6 * period_s)
    return None


def substeps_line(m, board, est, s):
    """the model's sub-steps at the estimator's period (docs/modules/model.md, "Sub-steps")"""
    rho_h, n = machine.model_substeps(m, est)
    line = "model step: rho h = %.2f (the presliding mode against the period), %d sub-step%s" % (
        rho_h, n, "" if n == 1 else "s")
    if n > machine.model_substep_bounds()[1]:
        line += ": more than BR_MODEL_SUB_MAX, the firmware refuses the estimator (br_model_init, BR_E_PARAM)"
    elif n > 1 and est == "pf" and s:
        # the PF's n > 1 pass runs the reference kernel's loop, not the core's own (not measured):
        # n times the measured particle-step is an estimate only
        with open(COST, encoding="utf-8") as f:
            per = json.load(f)[BOARDS[board][1]]["pf_per_particle_step"]
        extra = (n - 1) * per * m["estimator"]["pf"]["n_particles"]
        line += "; about %.0f %% of the period more if each sub-step cost a measured particle-step (not measured)" % (
            100.0 * extra / (s[0] / s[1]))
    elif n > 1:
        line += " (cost not measured)"
    return line


def transient_line(m, est):
    """(line, warn): the friction transient d over estimator est's period against the reference's"""
    d, _ = machine.transient_m(m, est)
    d_ref, _ = machine.transient_m(machine.load_or_exit(REFERENCE), est)
    ratio = d / d_ref
    line = ("friction transient over the period d = Fc T^2 / (2 Meff) = %.3g m, %.3g times the reference "
            "machine's %.3g m" % (d, ratio, d_ref))
    if est != "pf" or ratio < TRANSIENT_WARN_RATIO:
        return line, False
    return line + (": warning: on the fleet's axes with d this large the PF stopped the axis in most runs "
                   "(docs/fleet.md, \"Goals on the fleet\"); d falls with the period squared: a shorter "
                   "estimator period, or control.estimator none"), True


def main():
    if len(sys.argv) != 3 or sys.argv[2] not in BOARDS:
        sys.exit("usage: image_info.py MACHINE.json stm32h7|stm32g4")
    m = machine.load_or_exit(sys.argv[1])
    est, period = image(m, sys.argv[2])
    if est is None:
        sys.exit("%s: %s" % (sys.argv[1], period))
    s = share(m, sys.argv[2], est, period)
    cost = ("%.0f instructions per period, %.1f %% of it at 1 instruction per cycle (make target-bench's costs, "
            "target/mps2/measured_cost.json)" % (s[0], 100.0 * s[1])) if s else "its cost on this core not measured"
    print("  estimator: %s at %g ms; %s" % (est, period * 1e3, cost))
    if est in ("pf", "ukf"):
        print("  " + substeps_line(m, sys.argv[2], est, s))
        print("  " + transient_line(m, est)[0])
    return 0


if __name__ == "__main__":
    sys.exit(main())
