# SPDX-License-Identifier: Apache-2.0
"""The golden tests' tolerance constants are the ones docs/golden.md
justifies ("Tolerances"): each constant of a test_golden_*.c is read from
the C source and compared with the number docs/golden.md gives for it in
its section. A constant changed on one side only (a tolerance loosened in a
test, a factor edited in the docs) fails here, naming both places.

Usage: check_tolerances.py [--repo DIR]"""
import argparse
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))

NUM = r"([0-9]+(?:\.[0-9]*)?(?:e-?[0-9]+)?)"

# (test file, what, C regex, docs section heading, docs regex): each regex has
# one group, the number
CHECKS = [
    # ukf
    ("test_golden_ukf.c", "one-step factor C", rf"#define C_ONE_STEP {NUM}", "### ukf",
     rf"tolerance \(C = {NUM} one step"),
    ("test_golden_ukf.c", "free-run factor C", rf"#define C_FREE_RUN {NUM}", "### ukf",
     rf"tolerance \(C = [0-9]+ one step, {NUM} free run\)"),
    ("test_golden_ukf.c", "ukf_load free run from", rf"#define FREE_LOAD_FROM {NUM}", "### ukf",
     rf"FREE_LOAD_FROM = {NUM}"),
    ("test_golden_ukf.c", "ukf_ms free-run factor", rf"#define C_FREE_RUN_MS \({NUM} \* C_FREE_RUN\)", "### ukf",
     rf"C_FREE_RUN_MS = {NUM} × C_FREE_RUN"),
    ("test_golden_ukf.c", "ukf_glitch free-run factor", rf"#define C_FREE_RUN_GLITCH \({NUM} \* C_FREE_RUN\)",
     "### ukf", rf"C_FREE_RUN_GLITCH = {NUM} × C_FREE_RUN"),
    # ff_pred
    ("test_golden_ff_pred.c", "prediction", rf"#define C_PRED {NUM}", "### ff_pred", rf"\| dF \| {NUM}u·S"),
    # pf_ms
    ("test_golden_pf_ms.c", "one particle-step factor C_MS", rf"#define C_MS {NUM}", "### pf_ms",
     rf"C_MS = {NUM} u"),
    # model
    ("test_golden_model.c", "theta_1", rf"#define C_THETA {NUM}", "### model (", rf"\| θ₁ \| {NUM}u·S_θ"),
    ("test_golden_model.c", "omega_1", rf"#define C_OMEGA {NUM}", "### model (", rf"\| ω₁ \| {NUM}u·S_ω"),
    ("test_golden_model.c", "z_1", rf"#define C_Z {NUM}", "### model (", rf"\| z₁ \| {NUM}u·S_z"),
    ("test_golden_model.c", "f_nl", rf"#define C_FNL {NUM}", "### model (", rf"\| f_nl\(x_k\) \| {NUM}u·S_f"),
    # model_ext: theta_1 and z_1 "as model"
    ("test_golden_model_ext.c", "theta_1 (as model)", rf"#define C_THETA {NUM}", "### model (",
     rf"\| θ₁ \| {NUM}u·S_θ"),
    ("test_golden_model_ext.c", "z_1 (as model)", rf"#define C_Z {NUM}", "### model (", rf"\| z₁ \| {NUM}u·S_z"),
    ("test_golden_model_ext.c", "omega_1", rf"#define C_OMEGA {NUM}", "### model_ext", rf"\| ω₁ \| {NUM}u·S_ω"),
    ("test_golden_model_ext.c", "F_comp", rf"#define C_FNL {NUM}", "### model_ext", rf"\| F_comp\(x_k\) \| {NUM}u·"),
    # pf: the propagated bound D and the sums
    ("pf_bounds.h", "D_theta step", rf"#define C_THETA {NUM}", "### pf", rf"D_θ ← D_θ \+ h D_ω \+ {NUM}u S_θ"),
    ("pf_bounds.h", "D_omega step", rf"#define C_OMEGA {NUM}", "### pf", rf"D_ω ← D_ω \+ {NUM}u S_ω"),
    ("pf_bounds.h", "D_z step", rf"#define C_Z {NUM}", "### pf", rf"D_z ← D_z \+ 2hL D_ω \+ {NUM}u S_z"),
    ("pf_bounds.h", "D_g step", rf"#define C_GP {NUM}", "### pf", rf"D_g ← D_g \+ {NUM}u g_max"),
    ("pf_bounds.h", "log-weight rounding", rf"#define C_L {NUM}", "### pf", rf"\+ {NUM}u\\\|l\\\|"),
    ("pf_bounds.h", "f_nl in F-hat", rf"#define C_FNL {NUM}", "### pf", rf"\+ {NUM}u S_f,j"),
    ("pf_bounds.h", "float32 sums", rf"#define C_SUM {NUM}", "### pf", rf"D_i \+ {NUM}m·u"),
    ("pf_bounds.h", "br_exp_neg error", rf"#define EXP_REL {NUM}", "### pf", rf"ρ = {NUM} \+"),
    # pf_load: the common error's Kalman filter
    ("test_golden_pf_load.c", "Kalman rounding factor", rf"#define C_KF {NUM}", "### pf_load",
     rf"\(C_KF = {NUM}\)"),
    # qec
    ("test_golden_qec.c", "amplitude roundings", rf"#define C_AMP {NUM}", "### qec", rf"2\({NUM} \+ 4n\)u"),
    ("test_golden_qec.c", "per-period roundings", rf"#define C_STEP {NUM}", "### qec", rf"2\(2 \+ {NUM}n\)u"),
    ("test_golden_qec.c", "safety factor", rf"#define C_Q {NUM}", "### qec", rf"\| p \| {NUM}\(2 \+ 4n\)u"),
    # mslip
    ("test_golden_mslip.c", "element bound factor", rf"#define C_Z {NUM}", "### mslip",
     rf"\| z_i \| {NUM}·E_i"),
    ("test_golden_mslip.c", "force sum roundings", rf"#define C_F_SUM {NUM}", "### mslip",
     rf"\(n \+ {NUM}\)u·"),
    # model_ms
    ("test_golden_mslip.c", "theta_1", rf"#define C_THETA {NUM}", "### model_ms", rf"\| θ₁ \| {NUM}u·S_θ"),
    ("test_golden_mslip.c", "omega_1", rf"#define C_OMEGA {NUM}", "### model_ms", rf"\| ω₁ \| {NUM}u·S_ω"),
    ("test_golden_mslip.c", "z_1", rf"#define C_ZM {NUM}", "### model_ms", rf"\| z_i,1 \| {NUM}u·S_z"),
    ("test_golden_mslip.c", "f_nl", rf"#define C_FNL {NUM}", "### model_ms", rf"\| f_nl \| {NUM}u·"),
    # lugre
    ("test_golden_lugre.c", "drift factor", rf"#define C_DRIFT {NUM}", "### lugre", rf"\| z \| {NUM}·D_k"),
    ("test_golden_lugre.c", "g", rf"g, {NUM} \* U32 \* g\)", "### lugre", rf"\| g \| {NUM}u·g"),
    ("test_golden_lugre.c", "z rounding", rf"z_drift_tol \+ {NUM} \* U32", "### lugre", rf"\| z \| [0-9]+·D_k \+ {NUM}u"),
    ("test_golden_lugre.c", "F rounding", rf"F_drift_tol \+ {NUM} \* U32", "### lugre", rf"\| F \| σ0·[0-9]+·D_k \+ {NUM}u"),
    # ctrl
    ("test_golden_ctrl.c", "e_theta", rf"et, {NUM} \* U32 \* \(fabs\(et\) \+ rpc\)", "### ctrl", rf"\| e_θ \| {NUM}u\("),
    ("test_golden_ctrl.c", "omega", rf"w, {NUM} \* U32 \* fabs\(w\)\)", "### ctrl", rf"\| ω \| {NUM}u\\\|ω\\\|"),
    ("test_golden_ctrl.c", "eps", rf"eps_tol = {NUM} \* U32", "### ctrl", rf"\| ε \(after\) \| {NUM}u·Σ"),
    ("test_golden_ctrl.c", "tau", rf"tau_tol = {NUM} \* U32 \* S_u", "### ctrl", rf"\| τ \| {NUM}u·S_u"),
    ("test_golden_ctrl.c", "duty", rf"\+ {NUM} \* U32 \* fabs\(tau / tau_per_duty\)", "### ctrl",
     rf"\| duty \| tol_τ / tau_per_duty \+ {NUM}u"),
    # plant (double vs double: absolute tolerances)
    ("test_golden_plant.c", "theta", rf"#define TOL_THETA {NUM}", "### plant", rf"\| θ \| {NUM} rad"),
    ("test_golden_plant.c", "theta relative", rf"#define TOL_THETA_REL {NUM}", "### plant",
     rf"\| θ \| [0-9e.-]+ rad \+ {NUM}\\\|θ\\\|"),
    ("test_golden_plant.c", "omega", rf"#define TOL_OMEGA {NUM}", "### plant", rf"\| ω \| {NUM} rad/s"),
    ("test_golden_plant.c", "z", rf"#define TOL_Z {NUM}", "### plant", rf"\| z \| {NUM} m"),
    ("test_golden_plant.c", "f_nl", rf"#define TOL_FNL {NUM}", "### plant", rf"\| f_nl \| {NUM} N"),
    ("test_golden_plant.c", "z_i (Maxwell-slip)", rf"#define TOL_ZI {NUM}", "### plant",
     rf"\| z_i \(Maxwell-slip\) \| {NUM} m"),
    ("test_golden_plant.c", "f_nl (Maxwell-slip)", rf"#define TOL_FNL_GMS {NUM}", "### plant",
     rf"\| f_nl \(Maxwell-slip\) \| {NUM} N"),
    ("test_golden_plant.c", "encoder near an integer", rf"#define ENC_NEAR_INT {NUM}", "### plant",
     rf"nearest integer\\\| < {NUM}"),
]


def section(doc, heading):
    """The text of the docs section whose heading starts with `heading`, to the next heading of its level."""
    i = doc.find("\n" + heading)
    if i < 0:
        return None
    level = heading.split(" ")[0]
    j = re.search(rf"\n#{{1,{len(level)}}} ", doc[i + 1:])
    return doc[i + 1:i + 1 + j.start()] if j else doc[i + 1:]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repo", default=os.path.dirname(os.path.dirname(HERE)))
    a = ap.parse_args()
    doc_path = os.path.join(a.repo, "docs", "golden.md")
    doc = open(doc_path).read()
    fails, n = [], 0
    for test, what, c_re, heading, d_re in CHECKS:
        c_path = os.path.join(a.repo, "tests", "golden", test)
        src = open(c_path).read()
        cm = re.findall(c_re, src)
        sec = section(doc, heading)
        dm = re.findall(d_re, sec) if sec is not None else []
        if len(cm) != 1:
            fails.append(f"{test}: {what}: {len(cm)} matches of /{c_re}/ (one expected)")
            continue
        if not dm:
            fails.append(f"docs/golden.md, section '{heading}': {what}: no match of /{d_re}/")
            continue
        c_val, d_vals = float(cm[0]), {float(v) for v in dm}
        n += 1
        if d_vals != {c_val}:
            fails.append(f"{test}: {what} is {cm[0]}, docs/golden.md ('{heading}') says "
                         f"{' / '.join(sorted(set(dm)))}")
        else:
            print(f"  {test:26s} {what:26s} {cm[0]:>8s} = docs")
    for f in fails:
        print("FAIL: " + f, file=sys.stderr)
    print(f"{n - sum(1 for f in fails if ' says ' in f)} of {len(CHECKS)} tolerance constants equal docs/golden.md")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
