"""Command line (docs/diagnose.md):

  python -m bristle.diagnose diagnose --log LOG.csv --out DIR [--machine M.json] [--fc HZ] [--no-plots] [--quiet]
  python -m bristle.diagnose validate --model DIR/model.json --log OTHER.csv

(run with python/ on PYTHONPATH; `make diagnose` and `make validate` do that).
diagnose writes DIR/report.json, DIR/model.json, DIR/report.md and the figures;
validate prints the saved model's relerr on another log of the same machine.
Exit status: 0, 1 when the log, model or machine file cannot be used (a
message "file:line: problem" on stderr), 2 on a usage error.
"""
import argparse
import json
import math
import os
import sys

from . import causes, closedloop, logreader, model, report, signals

FIGURES = (
    ("force_fit.png", "measured force against the nominal and extended models' predictions, and the residuals"),
    ("residuals.png", "residuals against time, velocity and position"),
    ("residual_spectrum.png", "residual spectrum over position"),
    ("closed_loop.png", "closed-loop re-simulation against the measured position and force (controller known)"),
)


MACHINES_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "machines")


def _known_machine(log):
    """A machine file of python/bristle/diagnose/machines/ that lists the log's file name."""
    name = os.path.basename(log)
    for f in sorted(os.listdir(MACHINES_DIR)):
        p = os.path.join(MACHINES_DIR, f)
        try:
            with open(p, encoding="utf-8") as fh:
                if name in json.load(fh).get("logs", []):
                    return p
        except (OSError, json.JSONDecodeError, AttributeError):
            continue
    return None


def _machine(args):
    """The machine file: --machine, else <log>.machine.json beside the log,
    else one of python/bristle/diagnose/machines/ listing the log's name."""
    path = args.machine
    if path is None:
        side = os.path.splitext(args.log)[0] + ".machine.json"
        path = side if os.path.exists(side) else _known_machine(args.log)
    if path is None:
        return None, None
    try:
        with open(path, encoding="utf-8-sig") as f:
            m = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        raise closedloop.ControllerError(f"{path}: {e}") from None
    if not isinstance(m, dict):
        raise closedloop.ControllerError(f"{path}: a JSON object was expected")
    return m, path


def cmd_diagnose(args):
    say = (lambda s: None) if args.quiet else (lambda s: print(s, flush=True))
    machine, mpath = _machine(args)
    ctrl = None
    if machine and "controller" in machine:
        ctrl = closedloop.check_controller(machine["controller"], f"{mpath} (\"controller\")")
    log = logreader.read_log(args.log)
    say(f"{args.log}: {log.n} samples at {1e3 * log.dt:.4g} ms" +
        (f" (of {log.n_total}: the first {log.n} are used)" if log.n_total > log.n else ""))
    prep = signals.Prepared(log, fc_hz=args.fc)
    diag = causes.diagnose(prep, progress=say)
    closed = None
    if ctrl is not None:
        sims = {name: closedloop.resimulate(prep, f.params(), ctrl)
                for name, f in (("nominal", diag.nominal), ("extended", diag.extended))}
        closed = {"controller": f"{mpath} ({ctrl['type']})",
                  **{name: {k: v for k, v in s.items() if k.startswith("relerr")} for name, s in sims.items()}}
    os.makedirs(args.out, exist_ok=True)
    rep = report.build(prep, diag, machine=machine, closed=closed, log_path=args.log)
    report.write_json(os.path.join(args.out, "report.json"), rep)
    report.write_json(os.path.join(args.out, "model.json"), report.model_json(prep, diag, log_path=args.log))
    figs = [f for f in FIGURES if closed is not None or f[0] != "closed_loop.png"]
    if not args.no_plots:
        from . import plots
        plots.force_fit(os.path.join(args.out, "force_fit.png"), prep, diag)
        plots.residuals(os.path.join(args.out, "residuals.png"), prep, diag)
        plots.residual_spectrum(os.path.join(args.out, "residual_spectrum.png"), prep, diag)
        if closed is not None:
            plots.closed_loop(os.path.join(args.out, "closed_loop.png"), prep, sims)
    else:
        figs = []
    with open(os.path.join(args.out, "report.md"), "w", encoding="utf-8") as f:
        f.write(report.markdown(rep, figs))
    say(f"verdict: {rep['verdict']}; held-out relerr nominal {rep['nominal']['relerr_percent']:.4g} %, "
        f"extended {rep['extended']['relerr_percent']:.4g} %")
    if closed is not None:
        for name in ("nominal", "extended"):
            c = closed[name]
            say(f"closed loop ({name}): position {c['relerr_position_percent']:.3g} %, velocity "
                f"{c['relerr_velocity_percent']:.3g} %, force {c['relerr_force_percent']:.3g} %")
    say(f"wrote {args.out}/report.json, model.json, report.md" + (" and the figures" if figs else ""))
    return 0


# the model-file parameters each cause needs
CAUSE_PARAMS = {"offset": ["offset_N"], "asymmetric_friction": ["Fc_neg_N", "Fv_neg_Nspm"],
                "position_ripple": ["ripple_amp_N", "ripple_period_m", "ripple_phase_rad"],
                "position_gradient": ["grad_per_m"], "actuator_delay": ["delay_s"]}


def _line_of(text, key):
    """Line of the first "key" in a JSON text (1 when absent)."""
    i = text.find(f'"{key}"')
    return text.count("\n", 0, i) + 1 if i >= 0 else 1


def load_model(path):
    """A saved model file, checked: "file:line: problem" when it cannot be used."""
    try:
        with open(path, encoding="utf-8-sig") as f:
            text = f.read()
        m = json.loads(text)
    except OSError as e:
        raise logreader.LogError(path, 0, f"cannot open: {e.strerror}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise logreader.LogError(path, getattr(e, "lineno", 1), f"not JSON: {getattr(e, 'msg', e)}") from None
    if not isinstance(m, dict) or m.get("format") != report.MODEL_FORMAT:
        raise logreader.LogError(path, _line_of(text, "format"),
                                 f"not a model file (\"format\" must be \"{report.MODEL_FORMAT}\")")
    causes_ = m.get("causes", [])
    unknown = [c for c in causes_ if c not in model.CAUSES] if isinstance(causes_, list) else ["(not a list)"]
    if unknown:
        raise logreader.LogError(path, _line_of(text, "causes"), f"unknown cause(s) {', '.join(map(str, unknown))}")
    params = m.get("params")
    if not isinstance(params, dict):
        raise logreader.LogError(path, _line_of(text, "params"), "no \"params\" object")
    need = ["M_kg", "Fv_Nspm", "Fc_N", "Fs_N", "vs_mps", "sigma0_Npm"]
    for c in causes_:
        need += CAUSE_PARAMS[c]
    missing = [k for k in need if k not in params]
    if missing:
        raise logreader.LogError(path, _line_of(text, "params"), f"\"params\" lacks {', '.join(missing)}")
    bad = [k for k, v in params.items() if isinstance(v, bool) or not isinstance(v, (int, float))
           or not math.isfinite(v)]
    if bad:
        raise logreader.LogError(path, _line_of(text, bad[0]), f"parameter {bad[0]} is not a finite number")
    return m


def cmd_validate(args):
    m = load_model(args.model)
    log = logreader.read_log(args.log)
    prep = signals.Prepared(log, fc_hz=m.get("filter", {}).get("fc_hz", signals.FC_HZ))
    fit = model.from_params(m["params"], m.get("causes", []))
    w = prep.whole
    rel = fit.relerr(prep, w)
    line = (f"{args.log}: relerr {rel:.4g} % over {w.stop - w.start} samples (the whole log) with "
            f"{args.model} ({' + '.join(m.get('causes', [])) or 'nominal'})")
    if "nominal_params" in m:
        line += f"; nominal model {model.from_params(m['nominal_params'], ()).relerr(prep, w):.4g} %"
    print(line)
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m bristle.diagnose", description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    d = sub.add_parser("diagnose", help="fit, test the causes, report")
    d.add_argument("--log", required=True)
    d.add_argument("--out", required=True)
    d.add_argument("--machine", help="JSON with the controller (and published results); default: "
                                     "<log>.machine.json beside the log, else a file of python/bristle/diagnose/machines/ "
                                     "listing the log's name")
    d.add_argument("--fc", type=float, default=signals.FC_HZ, help="low-pass cutoff, Hz")
    d.add_argument("--no-plots", action="store_true")
    d.add_argument("--quiet", action="store_true")
    v = sub.add_parser("validate", help="relerr of a saved model on another log")
    v.add_argument("--model", required=True)
    v.add_argument("--log", required=True)
    args = ap.parse_args(argv)
    try:
        return cmd_diagnose(args) if args.cmd == "diagnose" else cmd_validate(args)
    except (logreader.LogError, closedloop.ControllerError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    except ValueError as e:  # too few samples for the split, a controller period mismatch
        print(f"error: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
