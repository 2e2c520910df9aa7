# SPDX-License-Identifier: Apache-2.0
"""model.json: the extended model a diagnosis saves, and its checked
loading (docs/diagnose.md, "Outputs" and "Parameters").

  format          "bristle-model/2"
  causes          the extended model's causes, in registry order
  params          its load-side parameters: params.NOMINAL and each cause's PARAMS
  nominal_params  the nominal model's
  filter          the low-pass the fit used (validate applies the same)
  presliding      with the cause presliding_hysteresis: its element set,
                  {"breakaway_m": [d_i at Fs_N, m], "share": [alpha_i, sum 1]}

The plant simulator reads the same "params" (sim/lib/plant/br_plant_json.c).
Format 1 (older names: M_kg, Fv_Nspm, Fc_neg_N, Fv_neg_Nspm) is not read."""
import math

from . import causes as causes_
from . import jsonfile, model, output, params, signals
from .logreader import LogError, short

MODEL_FORMAT = "bristle-model/2"
PRESLIDING = "presliding_hysteresis"
SHARE_TOL = 1e-6   # firmware/design/machine.py's MSLIP_SHARE_TOL
ELEMENTS_MAX = 8   # BR_MSLIP_MAX


def build(prep, diag, log_path=None):
    out = _build(prep, diag, log_path)
    if PRESLIDING in diag.extended.causes:
        out["presliding"] = presliding_elements(diag.extended.nl)
    return out


def presliding_elements(nl):
    """The element set as model.json and machine.json write it: breakaway
    displacements to 6 digits, shares to 6 decimals with the last one making
    the sum 1 (the machine file's loader accepts 1e-6)."""
    el = causes_.get(PRESLIDING).elements(nl)
    share = [round(a, 6) for a in el["share"][:-1]]
    share.append(round(1.0 - sum(share), 6))
    return {"breakaway_m": output.rounded(el["breakaway_m"]), "share": share}


def _build(prep, diag, log_path):
    return output.rounded({
        "generator": output.GENERATOR,
        "format": MODEL_FORMAT,
        "log": log_path or prep.path,
        "causes": list(diag.extended.causes),
        "filter": {"order": signals.ORDER, "fc_hz": prep.fc_hz},
        "params": diag.extended.params(),
        "nominal_params": diag.nominal.params(),
    })


def load(path):
    """A saved model file, checked: LogError "file:line: problem" when it
    cannot be used (not JSON, another format, an unknown cause, a parameter
    missing, unknown, of a cause it does not list, not a number, outside its
    bounds (params.Param), or two that break a relation (params.RELATIONS))."""
    m, text = jsonfile.load(path)
    if not isinstance(m, dict) or m.get("format") != MODEL_FORMAT:
        raise LogError(path, jsonfile.line_of(text, "format"), f"not a model file (\"format\" must be \"{MODEL_FORMAT}\")")
    listed = m.get("causes", [])
    unknown = ([short(str(c)) for c in listed if c not in causes_.NAMES] if isinstance(listed, list)
               else ["(not a list)"])
    if unknown:
        raise LogError(path, jsonfile.line_of(text, "causes"), f"unknown cause(s) {', '.join(unknown)}")
    twice = sorted({c for c in listed if listed.count(c) > 1})
    if twice:
        raise LogError(path, jsonfile.line_of(text, "causes"), f"field causes lists {', '.join(twice)} twice "
                                                               "(each cause once)")
    p = m.get("params")
    if not isinstance(p, dict):
        raise LogError(path, jsonfile.line_of(text, "params"), "no \"params\" object")
    need = params.NOMINAL + tuple(q for c in causes_.of(listed) for q in c.PARAMS)
    missing = [q.name for q in need if q.name not in p]
    if missing:
        raise LogError(path, jsonfile.line_of(text, "params"), f"\"params\" lacks {', '.join(missing)}")
    known = {q.name for q in need}
    for k in p:
        if k not in known:
            owner = [c.NAME for c in causes_.REGISTRY if any(q.name == k for q in c.PARAMS)]
            raise LogError(path, jsonfile.line_of(text, k), f"parameter {k} belongs to cause {owner[0]}, which "
                           "\"causes\" does not list" if owner else f"unknown parameter {short(k)}")
    for q in need:
        problem = q.check(p[q.name])
        if problem:
            raise LogError(path, jsonfile.line_of(text, q.name), problem)
    for names, holds, problem in params.RELATIONS:
        if all(k in p for k in names) and not holds(p):
            raise LogError(path, jsonfile.line_of(text, names[-1]), problem)
    nom = m.get("nominal_params")
    if nom is not None:
        where = path, jsonfile.line_of(text, "nominal_params")
        if not isinstance(nom, dict) or set(nom) != {q.name for q in params.NOMINAL}:
            raise LogError(*where, "\"nominal_params\" must hold exactly " + ", ".join(q.name for q in params.NOMINAL))
        for q in params.NOMINAL:
            problem = q.check(nom[q.name])
            if problem:
                raise LogError(*where, "\"nominal_params\": " + problem)
    _check_presliding(path, text, m, listed)
    filt = m.get("filter", {})
    fc = filt.get("fc_hz", signals.FC_HZ) if isinstance(filt, dict) else None
    problem = signals.FC_PARAM.check(fc)
    if problem:
        raise LogError(path, jsonfile.line_of(text, "fc_hz"), f"\"filter\": {problem}")
    return m


def _check_presliding(path, text, m, listed):
    """"presliding" is there exactly when the causes list presliding_hysteresis:
    1..8 breakaway displacements in (0, 1e-2] m and as many shares in (0, 1]
    summing to 1 within SHARE_TOL."""
    ps = m.get("presliding")
    where = path, jsonfile.line_of(text, "presliding")
    if PRESLIDING not in listed:
        if ps is not None:
            raise LogError(*where, f"\"presliding\" given but \"causes\" does not list {PRESLIDING}")
        return
    if not isinstance(ps, dict) or set(ps) != {"breakaway_m", "share"}:
        raise LogError(*where, f"{PRESLIDING} needs \"presliding\": {{\"breakaway_m\": [...], \"share\": [...]}}")
    d, a = ps["breakaway_m"], ps["share"]
    for name, v, hi in (("breakaway_m", d, 1e-2), ("share", a, 1.0)):
        if not isinstance(v, list) or not 1 <= len(v) <= ELEMENTS_MAX:
            raise LogError(*where, f"\"presliding\": {name} must be a list of 1 to {ELEMENTS_MAX} numbers")
        for x in v:
            if isinstance(x, bool) or not isinstance(x, (int, float)) or not 0.0 < x <= hi:
                raise LogError(*where, f"\"presliding\": {name} value {short(repr(x))} must be in (0, {hi:g}]")
    if len(d) != len(a):
        raise LogError(*where, f"\"presliding\": {len(a)} shares for {len(d)} breakaway displacements")
    if abs(math.fsum(a) - 1.0) > SHARE_TOL:
        raise LogError(*where, f"\"presliding\": the shares sum to {math.fsum(a):.9g}, must be 1 (within {SHARE_TOL:g})")


def fit_of(m):
    """The extended model of a checked model file as a Fit."""
    causes = m.get("causes", [])
    nl = causes_.get(PRESLIDING).from_elements(m["presliding"]) if PRESLIDING in causes else None
    return model.from_params(m["params"], causes, nl=nl)
