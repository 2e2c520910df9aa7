"""Command line (docs/diagnose.md):

  python -m bristle.diagnose diagnose --log LOG.csv --out DIR [--machine M.json] [--fc HZ] [--no-plots] [--quiet]
  python -m bristle.diagnose validate --model DIR/model.json --log OTHER.csv

(run with python/ on PYTHONPATH; `make diagnose` and `make validate` do that).
diagnose writes DIR/report.json, DIR/model.json, DIR/machine.json, DIR/report.md and the figures;
validate prints the saved model's relerr on another log of the same machine.
Exit status: 0, 1 when the log, model or machine file cannot be used (a
message "file:line: problem" on stderr), 2 on a usage error.
"""
import argparse
import math
import os
import sys

from . import (causes, closedloop, logreader, machinefile, machinejson, model, modelfile, output, report, selection,
               signals)

# figures: (file, what, function(path, prep, diag)); the causes' own between
# the residuals and the closed loop
FIGURES = (
    ("force_fit.png", "measured force against the nominal and extended models' predictions, and the residuals",
     lambda path, prep, diag: _plots().force_fit(path, prep, diag)),
    ("residuals.png", "residuals against time, velocity and position",
     lambda path, prep, diag: _plots().residuals(path, prep, diag)),
) + tuple(f for m in causes.REGISTRY for f in getattr(m, "FIGURES", ()))
CLOSED_LOOP_FIGURE = ("closed_loop.png",
                      "closed-loop re-simulation against the measured position and force (controller known)")


def _plots():
    from . import plots  # matplotlib: only when figures are drawn
    return plots


def check_out(out):
    """OUT before the fit: an existing directory, or a new one whose nearest
    existing parent is a directory this process may write in."""
    p = os.path.abspath(out)
    if os.path.exists(p):
        if not os.path.isdir(p):
            raise logreader.LogError(out, 0, "--out names an existing file, not a directory")
    else:
        while not os.path.exists(p):
            p = os.path.dirname(p)
        if not os.path.isdir(p):
            raise logreader.LogError(out, 0, f"--out cannot be created: {p} is not a directory")
    if not os.access(p, os.W_OK | os.X_OK):
        raise logreader.LogError(out, 0, f"--out cannot be written: no permission in {p}")


def cmd_diagnose(args):
    say = (lambda s: None) if args.quiet else (lambda s: print(s, flush=True))
    problem = signals.FC_PARAM.check(args.fc)
    if problem:
        raise logreader.LogError("--fc", 0, problem)
    check_out(args.out)
    # --machine names the log's controller file, or a firmware machine file
    # (checked here, before the fit) whose values machine.json takes
    given = machinejson.given(args.machine)
    mpath = machinefile.find(args.log, None if given else args.machine)
    machine, ctrl = machinefile.load(mpath) if mpath else (None, None)
    log = logreader.read_log(args.log)
    if ctrl is not None and abs(ctrl["dt_s"] - log.dt) > 1e-6 * log.dt:
        raise closedloop.ControllerError(f"{mpath}: controller period {ctrl['dt_s']:g} s differs from the log's "
                                         f"{log.dt:.6g} s")
    say(f"{args.log}: {log.n} samples at {1e3 * log.dt:.4g} ms" +
        (f" (of {log.n_total}: the first {log.n} are used)" if log.n_total > log.n else ""))
    prep = signals.Prepared(log, fc_hz=args.fc)
    diag = selection.diagnose(prep, progress=say)
    closed = None
    if ctrl is not None:
        try:
            sims = {name: closedloop.resimulate(prep, f.params(), ctrl)
                    for name, f in (("nominal", diag.nominal), ("extended", diag.extended))}
        except closedloop.ControllerError as e:
            raise closedloop.ControllerError(f"{mpath}: {e}") from None
        closed = {"controller": f"{mpath} ({ctrl['type']})",
                  **{name: {k: v for k, v in s.items() if k.startswith("relerr")} for name, s in sims.items()}}
    os.makedirs(args.out, exist_ok=True)
    rep = report.build(prep, diag, machine=machine, closed=closed, log_path=args.log)
    output.write_json(os.path.join(args.out, "report.json"), rep)
    output.write_json(os.path.join(args.out, "model.json"), modelfile.build(prep, diag, log_path=args.log))
    machinejson.write(args.out, prep, diag, given, args.log, say)
    figs = []
    if not args.no_plots:
        for name, what, draw in FIGURES:
            draw(os.path.join(args.out, name), prep, diag)
            figs.append((name, what))
        if closed is not None:
            _plots().closed_loop(os.path.join(args.out, CLOSED_LOOP_FIGURE[0]), prep, sims)
            figs.append(CLOSED_LOOP_FIGURE)
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


def cmd_validate(args):
    m = modelfile.load(args.model)
    log = logreader.read_log(args.log)
    prep = signals.Prepared(log, fc_hz=m.get("filter", {}).get("fc_hz", signals.FC_HZ))
    fit = model.from_params(m["params"], m.get("causes", []))
    w = prep.whole
    rel = fit.relerr(prep, w)
    if not math.isfinite(rel):
        raise ValueError(f"{args.model}: the model's prediction is not finite on this log")
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
    except ValueError as e:  # too few samples for the split, a singular fit
        print(f"error: {args.log}: {e}", file=sys.stderr)
        return 1
    except ArithmeticError as e:  # overflow, division by zero in degenerate data the guards let through
        print(f"error: {args.log}: numerical failure ({e})", file=sys.stderr)
        return 1
    except OSError as e:  # writing the outputs
        print(f"error: {e.filename or args.cmd}: {e.strerror}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
