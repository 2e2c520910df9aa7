"""report.json and report.md of a diagnosis (docs/diagnose.md); model.json
is modelfile.py's. Generated files carry output.GENERATOR and no timestamp,
numbers rounded (output.rounded), so that a rerun writes the same files."""
from . import causes as causes_
from . import model, output, selection, signals
from .evidence import Residual

# The EMPS paper's two IDIM-LS model structures (rigid + viscous + Coulomb as
# a sign function, no bristles, and one cause), refitted by this pipeline for
# every log: same filter, same split, same relerr, so that published figures
# compare with ours on equal terms.
PUBLISHED_STRUCTURES = (("rigid + viscous + symmetric Coulomb + offset", "offset"),
                        ("rigid + asymmetric viscous/Coulomb", "asymmetric_friction"))
SIGN_SHAPE = (model.RHO_BOUNDS[1], 1.0, 1.0)  # 1 nm presliding: Coulomb as sgn(v)


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
    return output.rounded(rep)


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
        L += [f"{i}. **{f['cause']}**, {causes_.get(f['cause']).MEANING} ({ps}): held-out relerr {f['relerr_before_percent']:.3g} % → "
              f"{f['relerr_after_percent']:.3g} % (p = {f['p_value']:.2g}). {f['evidence']}"]
    L += ["", "## Every cause tested", ""]
    for k, rnd in enumerate(rep["tested"], 1):
        L += [f"Round {k}:", "", "| cause | held-out relerr | relative gain | p | significant |", "|---|---|---|---|---|"]
        for c in rnd:
            L.append(f"| {c['cause']} | {c['relerr_percent']:.4g} % | {100 * c['relative_gain']:.3g} % | "
                     f"{c['p_value']:.2g} | {'yes' if c['significant'] else 'no'} |")
        L.append("")
    L += ["## Parameters (load side, model.json's)", "", "| parameter | unit | nominal | extended |", "|---|---|---|---|"]
    units = {q.name: q.unit for q in causes_.MODEL_PARAMS}
    keys = list(dict.fromkeys(list(rep["nominal"]["params"]) + list(rep["extended"]["params"])))
    for k in keys:
        L.append(f"| {k} | {units[k]} | {_fmt(rep['nominal']['params'].get(k))} | "
                 f"{_fmt(rep['extended']['params'].get(k))} |")
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
