"""report.json, model.json and report.md of a diagnosis (docs/diagnose.md).

Generated files carry a "generator" banner and no timestamp; numbers are
rounded to 6 significant digits so that a rerun on the same machine gives
the same files."""
import json
import math

import numpy as np

from . import causes, model, signals

GENERATOR = "python/bristle/diagnose (python -m bristle.diagnose); generated, do not edit"
MODEL_FORMAT = "bristle-model/1"


def _r(x):
    """6 significant digits (JSON-friendly, stable)."""
    if isinstance(x, dict):
        return {k: _r(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_r(v) for v in x]
    if isinstance(x, (bool, str)) or x is None:
        return x
    if isinstance(x, (int, np.integer)):
        return int(x)
    x = float(x)
    if not math.isfinite(x) or x == 0.0:
        return x if math.isfinite(x) else None
    return float(f"{x:.6g}")


def evidence(prep, nominal, cause, fit):
    """One sentence a person can check on the plots."""
    e = nominal.residual(prep)
    w = prep.whole
    v, x = prep.v[w], prep.xm[w]
    ew = e[w]
    moving = np.abs(v) > 0.2 * np.percentile(np.abs(v), 95)
    p = fit.cause_params(cause)
    if cause == "offset":
        rest = np.abs(v) < 0.02 * np.percentile(np.abs(v), 95)
        mp, mn = ew[moving & (v > 0)].mean(), ew[moving & (v < 0)].mean()
        at_rest = f", {ew[rest].mean():+.2f} N at rest" if rest.any() else ""
        return (f"The nominal model's residual has the same sign in both directions: {mp:+.2f} N moving in +x, "
                f"{mn:+.2f} N moving in -x{at_rest} (residual vs velocity); fitted constant force "
                f"{p['force_N']:+.3g} N.")
    if cause == "asymmetric_friction":
        vmax = np.percentile(np.abs(v), 95)
        fast = np.abs(v) > 0.6 * vmax
        slow = moving & ~fast
        parts = []
        for name, m in (("slow", slow), ("fast", fast)):
            if (m & (v > 0)).any() and (m & (v < 0)).any():
                parts.append(f"{name}: {ew[m & (v > 0)].mean():+.2f} N in +x, {ew[m & (v < 0)].mean():+.2f} N in -x")
        return ("The nominal model's residual differs by direction and speed (" + "; ".join(parts) +
                f"; residual vs velocity): friction in -x is {p['Fc_neg_N']:.3g} N + {p['Fv_neg_Nspm']:.4g} N s/m, "
                f"in +x {p['Fc_pos_N']:.3g} N + {p['Fv_pos_Nspm']:.4g} N s/m.")
    if cause == "position_ripple":
        return (f"The residual spectrum over position peaks at a period of {1e3 * p['period_m']:.3g} mm "
                f"(amplitude {p['amplitude_N']:.2g} N, residual spectrum plot), in both directions of motion "
                f"(residual vs position).")
    if cause == "position_gradient":
        sgn = np.sign(v[moving])
        lo, hi = np.percentile(x, [10, 90])
        xs = x[moving]
        rl = (ew[moving] * sgn)[xs < lo].mean() if (xs < lo).any() else 0.0
        rh = (ew[moving] * sgn)[xs > hi].mean() if (xs > hi).any() else 0.0
        s = p["relative_slope_per_m"]
        return (f"The residual in the direction of motion changes along the travel, {rl:+.2f} N near x = {lo:.3g} m "
                f"and {rh:+.2f} N near x = {hi:.3g} m (residual vs position): friction scales by 1 {s:+.3g} x "
                f"({100 * s * (hi - lo):+.1f} % between those positions).")
    if cause == "actuator_delay":
        da = np.abs(np.gradient(prep.a, prep.dt))[w]
        jerky = da > np.percentile(da, 90)
        r1 = float(np.sqrt(np.mean(ew[jerky] ** 2)))
        r0 = float(np.sqrt(np.mean(ew[~jerky] ** 2)))
        return (f"The residual concentrates where the acceleration changes (RMS {r1:.2f} N there against {r0:.2f} N "
                f"elsewhere, residual vs time) and shifting the logged force by {1e3 * p['delay_s']:.3g} ms removes it: "
                f"the force reaches the axis that much later than it is commanded.")
    raise ValueError(cause)


def published_structures(prep):
    """The EMPS paper's two IDIM-LS model structures (rigid + viscous +
    Coulomb as a sign function, no bristles, + offset; and the asymmetric
    one) refitted by this pipeline: same filter, same split, same relerr, so
    the published figures can be compared with ours on equal terms."""
    out = []
    sign_shape = (model.RHO_BOUNDS[1], 1.0, 1.0)  # 1 nm presliding: Coulomb sign(v)
    for name, cs in (("rigid + viscous + symmetric Coulomb + offset", ("offset",)),
                     ("rigid + asymmetric viscous/Coulomb", ("asymmetric_friction",))):
        nl = {"fc_ratio": 1.0} if "asymmetric_friction" in cs else {}
        f = model.solve(prep, sign_shape, cs, nl)
        if "asymmetric_friction" in cs:
            f = model.solve(prep, sign_shape, cs, {"fc_ratio": model.fit_fc_ratio(prep, f, cs, nl)})
        f.coef["sigma1"] = 0.0
        pr = f.params()
        keep = {k: pr[k] for k in ("M_kg", "Fv_Nspm", "Fc_N", "Fv_neg_Nspm", "Fc_neg_N", "offset_N") if k in pr}
        out.append({"name": name, "params": keep,
                    "relerr_percent": f.relerr(prep, prep.test),
                    "relerr_train_percent": f.relerr(prep, prep.train)})
    return out


def build(prep, diag, machine=None, closed=None, log_path=None):
    te, tr = prep.test, prep.train
    nom = diag.nominal
    findings = []
    for cand, refined in diag.findings:
        findings.append({
            "cause": cand.cause,
            "params": refined.cause_params(cand.cause),
            "relerr_after_percent": refined.relerr(prep, te),
            "relerr_before_percent": cand.base_relerr,
            "p_value": cand.p_value,
            "evidence": evidence(prep, nom, cand.cause, refined),
        })
    rep = {
        "generator": GENERATOR,
        "log": log_path or prep.path,
        "samples": int(len(prep.t)),
        "period_s": prep.dt,
        "method": {
            "filter": f"Butterworth order {signals.ORDER}, {prep.fc_hz:g} Hz, zero phase, on position and force",
            "held_out": prep.held_out_description(),
            "relerr": "100 ||y - yhat|| / ||y|| of the filtered force over the held-out part",
            "significance": {"min_relative_gain": causes.MIN_REL_GAIN, "blocks": causes.N_BLOCKS,
                             "test": "one-sided Wilcoxon signed-rank on the per-block drop of squared error",
                             "p_max": causes.P_MAX},
        },
        "nominal": {"params": nom.params(), "relerr_percent": nom.relerr(prep, te),
                    "relerr_train_percent": nom.relerr(prep, tr)},
        "findings": findings,
        "verdict": findings[0]["cause"] if findings else "none",
        "extended": {"causes": list(diag.extended.causes), "params": diag.extended.params(),
                     "relerr_percent": diag.extended.relerr(prep, te),
                     "relerr_train_percent": diag.extended.relerr(prep, tr)},
        "gain_percent_points": nom.relerr(prep, te) - diag.extended.relerr(prep, te),
        "tested": diag.rounds,
        "published_structures_refitted": published_structures(prep),
    }
    if machine:
        rep["machine"] = {k: machine[k] for k in ("name", "source") if k in machine}
        if "published" in machine:
            rep["published"] = machine["published"]
    if closed:
        rep["closed_loop"] = closed
    return _r(rep)


def model_json(prep, diag, log_path=None):
    return _r({
        "generator": GENERATOR,
        "format": MODEL_FORMAT,
        "log": log_path or prep.path,
        "causes": list(diag.extended.causes),
        "filter": {"order": signals.ORDER, "fc_hz": prep.fc_hz},
        "params": diag.extended.params(),
        "nominal_params": diag.nominal.params(),
    })


def write_json(path, obj):
    with open(path, "w", encoding="utf-8") as f:
        json.dump(obj, f, indent=2)
        f.write("\n")


def _fmt(v, unit=""):
    if v is None:
        return "—"
    return f"{v:.4g}{unit}"


def markdown(rep, figures):
    L = [f"<!-- {rep['generator']} -->", "", f"# Diagnosis of `{rep['log']}`", ""]
    L += [f"{rep['samples']} samples at {1e3 * rep['period_s']:.4g} ms. Held out: {rep['method']['held_out']}.", ""]
    L += [f"**Verdict: {rep['verdict']}**", ""]
    L += ["| model | held-out relerr | training relerr |", "|---|---|---|",
          f"| nominal (rigid + viscous + symmetric LuGre) | {_fmt(rep['nominal']['relerr_percent'], ' %')} | "
          f"{_fmt(rep['nominal']['relerr_train_percent'], ' %')} |",
          f"| extended ({' + '.join(rep['extended']['causes']) or 'nothing added'}) | "
          f"{_fmt(rep['extended']['relerr_percent'], ' %')} | {_fmt(rep['extended']['relerr_train_percent'], ' %')} |"]
    for s in rep["published_structures_refitted"]:
        L.append(f"| {s['name']} (published structure, refitted here) | {_fmt(s['relerr_percent'], ' %')} | "
                 f"{_fmt(s['relerr_train_percent'], ' %')} |")
    if "published" in rep:
        for m in rep["published"]["models"]:
            L.append(f"| {m['name']} (published) | — | {_fmt(m['relerr_percent'], ' %')} (whole run, decimated) |")
    L.append("")
    L += [f"Gain of the extended model on the held-out part: {rep['gain_percent_points']:.3g} percentage points.", ""]
    L += ["## Findings (strongest first)", ""]
    if not rep["findings"]:
        L += ["None: no cause improves the held-out error significantly.", ""]
    for i, f in enumerate(rep["findings"], 1):
        ps = ", ".join(f"{k} = {v:.4g}" for k, v in f["params"].items())
        L += [f"{i}. **{f['cause']}** ({ps}): held-out relerr {f['relerr_before_percent']:.3g} % → "
              f"{f['relerr_after_percent']:.3g} % (p = {f['p_value']:.2g}). {f['evidence']}"]
    L += ["", "## Every cause tested", ""]
    for k, rnd in enumerate(rep["tested"], 1):
        L += [f"Round {k}:", "", "| cause | held-out relerr | relative gain | p | significant |", "|---|---|---|---|---|"]
        for c in rnd:
            L.append(f"| {c['cause']} | {c['relerr_percent']:.4g} % | {100 * c['relative_gain']:.3g} % | "
                     f"{c['p_value']:.2g} | {'yes' if c['significant'] else 'no'} |")
        L.append("")
    L += ["## Parameters (load side)", "", "| parameter | nominal | extended |", "|---|---|---|"]
    keys = list(dict.fromkeys(list(rep["nominal"]["params"]) + list(rep["extended"]["params"])))
    for k in keys:
        L.append(f"| {k} | {_fmt(rep['nominal']['params'].get(k))} | {_fmt(rep['extended']['params'].get(k))} |")
    L.append("")
    if "closed_loop" in rep:
        cl = rep["closed_loop"]
        L += ["## Closed-loop re-simulation", "",
              "The log's reference through the known controller and the fitted model as the plant, whole run; "
              "velocity and force compared after the diagnosis filter.", "",
              "| model | position relerr | velocity relerr | acceleration relerr | force relerr |",
              "|---|---|---|---|---|"]
        for name in ("nominal", "extended"):
            r = cl[name]
            L.append(f"| {name} | {r['relerr_position_percent']:.3g} % | {r['relerr_velocity_percent']:.3g} % | "
                     f"{r['relerr_acceleration_percent']:.3g} % | {r['relerr_force_percent']:.3g} % |")
        pub = rep.get("published", {}).get("closed_loop")
        if pub:
            L.append(f"| published ({pub['model']}) | {pub['relerr_position_percent']:.3g} % | "
                     f"{pub['relerr_velocity_percent']:.3g} % | {pub['relerr_acceleration_percent']:.3g} % | "
                     f"{pub['relerr_force_percent']:.3g} % |")
        L.append("")
    L += ["## Figures", ""] + [f"- `{name}`: {what}" for name, what in figures] + [""]
    L += ["## Method", "", f"- filter: {rep['method']['filter']}", f"- relerr: {rep['method']['relerr']}",
          f"- a cause is significant when the held-out relerr drops by at least "
          f"{100 * rep['method']['significance']['min_relative_gain']:g} % of the base model's and the drop is "
          f"consistent over {rep['method']['significance']['blocks']} blocks of the held-out part "
          f"({rep['method']['significance']['test']}, p < {rep['method']['significance']['p_max']:g})",
          "- docs/diagnose.md explains the models and the tests", ""]
    return "\n".join(L)
