"""model.json: the extended model a diagnosis saves, and its checked
loading (docs/diagnose.md, "Outputs" and "Parameters").

  format          "bristle-model/2"
  causes          the extended model's causes, in registry order
  params          its load-side parameters: params.NOMINAL and each cause's PARAMS
  nominal_params  the nominal model's
  filter          the low-pass the fit used (validate applies the same)

The plant simulator reads the same "params" (sim/plant/br_plant_json.c).
Format 1 (older names: M_kg, Fv_Nspm, Fc_neg_N, Fv_neg_Nspm) is not read."""
import json

from . import causes as causes_
from . import checks, output, params, signals
from .logreader import LogError

MODEL_FORMAT = "bristle-model/2"


def build(prep, diag, log_path=None):
    return output.rounded({
        "generator": output.GENERATOR,
        "format": MODEL_FORMAT,
        "log": log_path or prep.path,
        "causes": list(diag.extended.causes),
        "filter": {"order": signals.ORDER, "fc_hz": prep.fc_hz},
        "params": diag.extended.params(),
        "nominal_params": diag.nominal.params(),
    })


def _line_of(text, key):
    """Line of the first "key" in a JSON text (1 when absent)."""
    i = text.find(f'"{key}"')
    return text.count("\n", 0, i) + 1 if i >= 0 else 1


def load(path):
    """A saved model file, checked: LogError "file:line: problem" when it
    cannot be used (not JSON, another format, an unknown cause, a parameter
    missing, unknown, of a cause it does not list, not finite, or not > 0
    where it must be)."""
    try:
        with open(path, encoding="utf-8-sig") as f:
            text = f.read()
        m = json.loads(text)
    except OSError as e:
        raise LogError(path, 0, f"cannot open: {e.strerror}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise LogError(path, getattr(e, "lineno", 1), f"not JSON: {getattr(e, 'msg', e)}") from None
    if not isinstance(m, dict) or m.get("format") != MODEL_FORMAT:
        raise LogError(path, _line_of(text, "format"), f"not a model file (\"format\" must be \"{MODEL_FORMAT}\")")
    listed = m.get("causes", [])
    unknown = [c for c in listed if c not in causes_.NAMES] if isinstance(listed, list) else ["(not a list)"]
    if unknown:
        raise LogError(path, _line_of(text, "causes"), f"unknown cause(s) {', '.join(map(str, unknown))}")
    p = m.get("params")
    if not isinstance(p, dict):
        raise LogError(path, _line_of(text, "params"), "no \"params\" object")
    need = params.NOMINAL + tuple(q for c in causes_.of(listed) for q in c.PARAMS)
    missing = [q.name for q in need if q.name not in p]
    if missing:
        raise LogError(path, _line_of(text, "params"), f"\"params\" lacks {', '.join(missing)}")
    known = {q.name for q in need}
    for k in p:
        if k not in known:
            owner = [c.NAME for c in causes_.REGISTRY if any(q.name == k for q in c.PARAMS)]
            raise LogError(path, _line_of(text, k), f"parameter {k} belongs to cause {owner[0]}, which \"causes\" "
                           "does not list" if owner else f"unknown parameter {k}")
    for q in need:
        if not checks.finite(p[q.name], q.positive):
            raise LogError(path, _line_of(text, q.name),
                           f"parameter {q.name} is not a finite number" + (" > 0" if q.positive else ""))
    return m
