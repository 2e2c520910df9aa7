# SPDX-License-Identifier: Apache-2.0
"""report.json and report.md of a diagnosis (docs/diagnose.md); model.json
is modelfile.py's. Generated files carry output.GENERATOR and no timestamp,
numbers rounded (output.rounded), so that a rerun writes the same files."""
from . import causes as causes_
from . import intervals, model, noise, output, plausible, selection, signals, unexplained
from .evidence import Residual

# The EMPS paper's two IDIM-LS model structures (rigid + viscous + Coulomb as
# a sign function, no bristles, and one cause), refitted by this pipeline for
# every log: same filter, same split, same relerr, so that published figures
# compare with ours on equal terms.
PUBLISHED_STRUCTURES = (("rigid + viscous + symmetric Coulomb + offset", "offset"),
                        ("rigid + asymmetric viscous/Coulomb", "asymmetric_friction"))
SIGN_SHAPE = (model.RHO_BOUNDS[1], 1.0, 1.0)  # 1 nm presliding: Coulomb as sgn(v)


# figures of every report (beside __main__'s and the causes'): (file, what, function(path, prep, diag))
FIGURES = (
    ("friction_map.png", "friction against velocity by direction, with the fitted models' steady friction",
     lambda path, prep, diag: _plots().friction_map(path, prep, diag)),
    ("unexplained.png", "what the extended model's residual goes with: time, position, velocity, acceleration, "
                        "direction, time since a reversal",
     lambda path, prep, diag: unexplained.figure(path, prep, diag)),
)


def _plots():
    from . import plots  # matplotlib: only when figures are drawn
    return plots


CLOSED_LOOP_SKIPPED = ("The closed loop was not re-simulated: no machine file gives this log's position controller "
                       "(pass --machine FILE, or put <log>.machine.json beside the log; docs/diagnose.md, Machine "
                       "files).")


def evidence(prep, nominal, cause, fit):
    """One sentence a person can check on the plots (the cause module's)."""
    return causes_.get(cause).evidence(Residual(prep, nominal.residual(prep)), fit.cause_params(cause))


def published_structures(prep):
    out = []
    base = model.solve(prep, SIGN_SHAPE, (), {})
    for name, cause in PUBLISHED_STRUCTURES:
        f = model.add_cause(prep, base, cause)
        f.coef["sigma1"] = 0.0
        pr = f.params()
        keep = ("Meff_kg", "sigma2_Nspm", "Fc_N") + tuple(q.name for q in causes_.get(cause).PARAMS)
        out.append({"name": name, "params": {k: pr[k] for k in keep},
                    "relerr_percent": f.relerr(prep, prep.test),
                    "relerr_train_percent": f.relerr(prep, prep.train)})
    return out


def verdict(prep, diag, floor):
    """The spec's verdict and `unexplained` object: the first finding; else
    "none" when the nominal model's held-out residual is at the log's noise
    floor (noise.py), "unexplained" when it is above. `unexplained` is
    described whenever the best model's residual stays above the floor."""
    ext_rel = diag.extended.relerr(prep, prep.test)
    above = not floor.at_floor(ext_rel)
    une = unexplained.describe(prep, diag.extended, floor, ext_rel) if above else None
    if diag.findings:
        return diag.findings[0][0].cause, une
    return ("unexplained" if above else "none"), une


def build(prep, diag, machine=None, closed=None, log_path=None, floor=None):
    te, tr = prep.test, prep.train
    nom = diag.nominal
    floor = floor or noise.measure(prep, diag.nominal)
    verdict_, une = verdict(prep, diag, floor)
    findings = []
    ext = diag.extended
    ivals = intervals.jackknife(prep, ext)
    ext_params = ext.params()
    unident = intervals.unidentified(prep, ext_params, ivals)
    ident = getattr(diag, "identifiability", None)
    if ident:
        for k, h in list(ident["held"].items()) + list(ident["poorly_determined"].items()):
            unident[k] = h["why"]
        unident.update(ident.get("kept_out", {}))
    for cand, refined in diag.findings:
        mod = causes_.get(cand.cause)
        findings.append({
            "cause": cand.cause,
            # the final joint model's parameters (selection.py)
            "params": ext.cause_params(cand.cause),
            "intervals_95": {k: list(ivals[f"{cand.cause}.{k}"]) for k in ext.cause_params(cand.cause)
                             if f"{cand.cause}.{k}" in ivals},
            "meaning": mod.MEANING,
            "action": getattr(mod, "ACTION", "see docs/diagnose.md, Causes"),
            "relerr_after_percent": refined.relerr(prep, te),
            "relerr_before_percent": cand.base_relerr,
            "p_value": cand.p_value,
            "evidence": evidence(prep, nom, cand.cause, ext),
        })
    rep = {
        "generator": output.GENERATOR,
        "log": log_path or prep.path,
        "samples": int(len(prep.t)),
        "period_s": prep.dt,
        "method": {
            "filter": f"Butterworth order {signals.ORDER}, {prep.fc_hz:g} Hz, zero phase, on position and force",
            "held_out": prep.held_out_description(),
            "relerr": "100 ||y - yhat|| / ||y|| of the filtered force over the held-out part",
            "significance": {"min_relative_gain": selection.MIN_REL_GAIN, "blocks": selection.N_BLOCKS,
                             "test": "one-sided Wilcoxon signed-rank on the per-block drop of squared error",
                             "p_max": selection.P_MAX},
        },
        "nominal": {"params": nom.params(), "relerr_percent": nom.relerr(prep, te),
                    "relerr_train_percent": nom.relerr(prep, tr)},
        "findings": findings,
        "verdict": verdict_,
        "borderline": [dict(c, meaning=causes_.get(c["cause"]).MEANING) for c in selection.borderline(diag)],
        "dropped": diag.dropped,
        "swapped": diag.swapped,
        "extended": {"causes": list(diag.extended.causes), "params": ext_params,
                     "intervals_95": {k: list(v) for k, v in ivals.items() if "." not in k},
                     "not_identified": unident,
                     "relerr_percent": diag.extended.relerr(prep, te),
                     "relerr_train_percent": diag.extended.relerr(prep, tr)},
        "gain_percent_points": nom.relerr(prep, te) - diag.extended.relerr(prep, te),
        "identifiability": ident,
        "noise_floor_percent": floor.percent,
        "noise_floor": floor.summary(),
        "unexplained": une,
        "tested": diag.rounds,
        "tested_pairs": diag.pairs,
        "published_structures_refitted": published_structures(prep),
    }
    if machine:
        rep["machine"] = {k: machine[k] for k in ("name", "source") if k in machine}
        if "published" in machine:
            rep["published"] = machine["published"]
    if closed:
        rep["closed_loop"] = closed
    else:
        rep["closed_loop_skipped"] = CLOSED_LOOP_SKIPPED
    return output.rounded(rep)


def _param(k, v):
    """"name = value" of a report parameter; an element set as its (breakaway, share) pairs."""
    if isinstance(v, list):
        return f"{k} = " + ", ".join(f"({e['breakaway_m']:.3g} m, {e['share']:.3g})" for e in v)
    return f"{k} = {v:.4g}"


def _fmt(v, unit=""):
    if v is None:
        return "—"
    return f"{v:.4g}{unit}"


def markdown(rep, figures):
    L = [f"<!-- {rep['generator']} -->", "", f"# Diagnosis of `{rep['log']}`", ""]
    L += [f"{rep['samples']} samples at {1e3 * rep['period_s']:.4g} ms. Held out: {rep['method']['held_out']}.", ""]
    L += [f"**Verdict: {rep['verdict']}**", ""]
    for line in plausible.describe(rep.get("impossible_samples")):
        L += [f"Impossible samples: {line}.", ""]
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
    fl = rep["noise_floor"]
    L += [f"Noise floor measured from the log: {_fmt(rep['noise_floor_percent'], ' %')} held-out relerr: "
          f"force noise {fl['force_noise_N']:.3g} N (from the force above {fl['band_hz'][0]:.3g} Hz) "
          f"{_fmt(fl['noise_percent'], ' %')}, encoder step {fl['position_step_m']:.3g} m "
          f"{_fmt(fl['resolution_percent'], ' %')}; a residual up to {_fmt(fl['at_floor_threshold_percent'], ' %')} "
          "is at the floor.", ""]
    L += ["## Findings (strongest first)", ""]
    if not rep["findings"]:
        L += [("None: no cause improves the held-out error significantly, and the nominal model's residual is at "
               "the noise floor." if rep["verdict"] == "none" else
               "No named cause improves the held-out error significantly, but the nominal model's residual is "
               "above the noise floor: see Unexplained."), ""]
    for i, f in enumerate(rep["findings"], 1):
        ps = ", ".join(_param(k, v) + (f" [{f['intervals_95'][k][0]:.4g} .. {f['intervals_95'][k][1]:.4g}]"
                                            if k in f.get("intervals_95", {}) else "")
                       for k, v in f["params"].items())
        L += [f"{i}. **{f['cause']}**: {f['meaning']}. Parameters of the joint model with 95 % intervals: {ps}. "
              f"Held-out relerr {f['relerr_before_percent']:.3g} % → {f['relerr_after_percent']:.3g} % when it was "
              f"added (p = {f['p_value']:.2g}). {f['evidence']}", "",
              f"   *What to check or do:* {f['action']}", ""]
    if rep.get("borderline"):
        L += ["Borderline (significant only at the looser level: relative gain ≥ "
              f"{100 * selection.BORDERLINE_GAIN:g} %, p < {selection.BORDERLINE_P:g}; not findings, not in the "
              "model; worth a second log):", ""]
        for c in rep["borderline"]:
            ps = ", ".join(_param(k, v) for k, v in c["params"].items())
            L.append(f"- {c['cause']} ({c['meaning']}; {ps}): held-out relerr {c['base_relerr_percent']:.4g} % → "
                     f"{c['relerr_percent']:.4g} % ({100 * c['relative_gain']:.3g} %, p = {c['p_value']:.2g})")
            moves = ((rep.get("identifiability") or {}).get("borderline_moves") or {}).get(c["cause"])
            if moves:
                L.append("  - added to the model it moves " + "; ".join(
                    f"`{k}` {a:.4g} → {b:.4g} (95 % interval {iv[0]:.4g} .. {iv[1]:.4g})"
                    for k, (a, b, iv) in moves.items()) + "; a move by more than half the value keeps the parameter out of "
                    "machine.json")
        L.append("")
    for c in rep.get("dropped", []):
        L += [f"Dropped: {c['cause']} was found in round {c['round']} and left the joint model when later findings "
              f"explained it (held-out relerr without it {c['base_relerr_percent']:.4g} %, with it "
              f"{c['relerr_percent']:.4g} %, p = {c['p_value']:.2g}).", ""]
    for c in rep.get("swapped", []):
        L += [f"Swapped: {c['out']} was replaced by {c['cause']} in round {c['round']} (held-out relerr "
              f"{c['base_relerr_percent']:.4g} % → {c['relerr_percent']:.4g} %, p = {c['p_value']:.2g}): it had "
              "stood in for it.", ""]
    L += ["## Unexplained", ""]
    une = rep.get("unexplained")
    if une is None:
        L += ["Nothing: the extended model's held-out residual is at the noise floor.", ""]
    else:
        sh = ", ".join(f"{k} {100 * v:.1f} %" for k, v in une["shares"].items())
        L += [une["evidence"], "", f"Share of the residual each signal explains: {sh} (`unexplained.png`).", ""]
    ni = rep["extended"].get("not_identified", {})
    if ni:
        L += ["## Parameters this log cannot identify", ""] + [f"- `{k}`: {why}" for k, why in ni.items()] + [""]
    L += ["", "## Every cause tested", ""]
    for k, rnd in enumerate(rep["tested"], 1):
        L += [f"Round {k}:", "", "| cause | held-out relerr | relative gain | p | significant |", "|---|---|---|---|---|"]
        for c in rnd:
            L.append(f"| {c['cause']} | {c['relerr_percent']:.4g} % | {100 * c['relative_gain']:.3g} % | "
                     f"{c['p_value']:.2g} | {'yes' if c['significant'] else 'no'} |")
        L.append("")
        prs = [c for c in rep.get("tested_pairs", []) if c["round"] == k]
        if prs:
            L += [f"No cause was significant alone in round {k}; pairs tested jointly (selection.py, Pairs):", "",
                  "| causes | held-out relerr | relative gain | p | each needed in the pair | significant |",
                  "|---|---|---|---|---|---|"]
            for c in prs:
                need = ", ".join(f"{k} {'yes' if v else 'no'}" for k, v in c.get("needed", {}).items()) or "—"
                L.append(f"| {' + '.join(c['causes'])} | {c['relerr_percent']:.4g} % | "
                         f"{100 * c['relative_gain']:.3g} % | {c['p_value']:.2g} | {need} | "
                         f"{'yes' if c['significant'] else 'no'} |")
            L.append("")
    L += ["## Parameters (load side, model.json's)", "",
          "| parameter | unit | nominal | extended | 95 % interval (jackknife over training blocks) |",
          "|---|---|---|---|---|"]
    iv = rep["extended"].get("intervals_95", {})
    units = {q.name: q.unit for q in causes_.MODEL_PARAMS}
    keys = list(dict.fromkeys(list(rep["nominal"]["params"]) + list(rep["extended"]["params"])))
    for k in keys:
        flag = " (not identified)" if k in ni else ""
        L.append(f"| {k} | {units[k]} | {_fmt(rep['nominal']['params'].get(k))} | "
                 f"{_fmt(rep['extended']['params'].get(k))}{flag} | "
                 + (f"{iv[k][0]:.4g} .. {iv[k][1]:.4g} |" if k in iv else "— |"))
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
    else:
        L += ["## Closed-loop re-simulation", "", rep["closed_loop_skipped"], ""]
    L += ["## Figures", ""] + [f"- `{name}`: {what}" for name, what in figures] + [""]
    L += ["## Method", "", f"- filter: {rep['method']['filter']}", f"- relerr: {rep['method']['relerr']}",
          f"- a cause is significant when the held-out relerr drops by at least "
          f"{100 * rep['method']['significance']['min_relative_gain']:g} % of the base model's and the drop is "
          f"consistent over {rep['method']['significance']['blocks']} blocks of the held-out part "
          f"({rep['method']['significance']['test']}, p < {rep['method']['significance']['p_max']:g})",
          "- docs/diagnose.md explains the models and the tests", ""]
    return "\n".join(L)
