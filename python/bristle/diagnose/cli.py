# SPDX-License-Identifier: Apache-2.0
"""Command line of the diagnosis (docs/diagnose.md), installed as `bristle-diagnose`:

  bristle-diagnose diagnose --log LOG.csv --out DIR [--machine M.json] [--fc HZ] [--no-plots] [-q | -v]
  bristle-diagnose validate --model DIR/model.json --log OTHER.csv [-q | -v]

(from the source tree: PYTHONPATH=python python -m bristle.diagnose ...;
`make diagnose` and `make validate` run that).
diagnose writes DIR/report.json, DIR/model.json, DIR/machine.json, DIR/report.md
and the figures; validate writes the saved model's relerr on another log of
the same machine to standard output (its result, one line).
Messages (progress, the verdict, errors) are logged to standard error:
--quiet keeps warnings and errors, --verbose adds debug detail.
"""
import argparse
import logging
import math
import os
import sys
import time

from .. import __version__
from . import (causes, closedloop, identify, logreader, machinefile, machinejson, model, modelfile, output, plausible,
               report, selection, signals, units)

# Exit statuses (docs/diagnose.md, "Exit status")
EXIT_OK = 0
EXIT_INPUT = 1   # a log, model or machine file cannot be used, or an output cannot be written ("file:line: problem")
EXIT_USAGE = 2   # the command line is wrong (argparse's own status)

EPILOG = ("exit status: 0 success; 1 a log, model or machine file cannot be used, or an output cannot be "
          "written (a message \"error: file:line: problem\" on standard error); 2 a usage error")

log = logging.getLogger("bristle.diagnose")

# figures: (file, what, function(path, prep, diag)); the causes' own between
# the residuals and the closed loop
FIGURES = (
    ("force_fit.png", "measured force against the nominal and extended models' predictions, and the residuals",
     lambda path, prep, diag: _plots().force_fit(path, prep, diag)),
    ("residuals.png", "residuals against time, velocity and position",
     lambda path, prep, diag: _plots().residuals(path, prep, diag)),
) + report.FIGURES + tuple(f for m in causes.REGISTRY for f in getattr(m, "FIGURES", ()))
CLOSED_LOOP_FIGURE = ("closed_loop.png",
                      "closed-loop re-simulation against the measured position and force (controller known)")


def _plots():
    from . import plots  # matplotlib: only when figures are drawn
    return plots


# what a diagnosis writes into OUT (output.check_out: OUT is replaced as a whole)
OUTPUT_NAMES = frozenset(("report.json", "model.json", "machine.json", "report.md", CLOSED_LOOP_FIGURE[0]) +
                         tuple(f[0] for f in FIGURES))


def check_out(out):
    """OUT before the fit (output.check_out): new, empty or a previous
    diagnosis's, in a folder this process may write in."""
    problem = output.check_out(out, OUTPUT_NAMES)
    if problem:
        raise logreader.LogError(out, 0, problem)


def cmd_diagnose(args):
    say = log.info
    problem = signals.FC_PARAM.check(args.fc)
    if problem:
        raise logreader.LogError("--fc", 0, problem)
    check_out(args.out)
    # --machine names the log's controller file, or a firmware machine file
    # (checked here, before the fit) whose values machine.json takes
    given = machinejson.given(args.machine)
    mpath = machinefile.find(args.log, None if given else args.machine)
    log.debug("machine file: %s; firmware machine file: %s", mpath or "none", given or "none")
    machine, ctrl = machinefile.load(mpath) if mpath else (None, None)
    t0 = time.monotonic()
    lg = logreader.read_log(args.log)
    log.debug("read %s in %.2f s", args.log, time.monotonic() - t0)
    base = machinejson.base(given)
    units.check(lg, base)  # seconds, metres, newtons: a log 1000 times off is refused naming the unit
    if ctrl is not None and abs(ctrl["dt_s"] - lg.dt) > 1e-6 * lg.dt:
        raise closedloop.ControllerError(f"{mpath}: controller period {ctrl['dt_s']:g} s differs from the log's "
                                         f"{lg.dt:.6g} s")
    say(f"{args.log}: {lg.n} samples at {1e3 * lg.dt:.4g} ms" +
        (f" (of {lg.n_total}: the first {lg.n} are used)" if lg.n_total > lg.n else ""))
    # samples no axis within the machine's limits produces: replaced, or the log refused
    impossible = plausible.check(lg, given)
    for line in plausible.describe(impossible):
        log.warning("%s: %s", args.log, line)
    prep = signals.Prepared(lg, fc_hz=args.fc)
    log.debug("low-pass cutoff %g Hz", args.fc)
    t0 = time.monotonic()
    diag = selection.diagnose(prep, progress=say)
    # what the log cannot identify: held at the machine file's values (identify.py)
    diag.identifiability = identify.apply(prep, diag, identify.prior(base), say=say)
    log.debug("fits and cause tests in %.2f s", time.monotonic() - t0)
    closed = None
    if ctrl is not None:
        try:
            sims = {name: closedloop.resimulate(prep, f.params(), ctrl)
                    for name, f in (("nominal", diag.nominal), ("extended", diag.extended))}
        except closedloop.ControllerError as e:
            raise closedloop.ControllerError(f"{mpath}: {e}") from None
        closed = {"controller": f"{mpath} ({ctrl['type']})",
                  **{name: {k: v for k, v in s.items() if k.startswith("relerr")} for name, s in sims.items()}}
    # every output into a staging folder that takes OUT's place at the end (output.Staging)
    with output.Staging(args.out) as stage:
        out = stage.dir
        rep = report.build(prep, diag, machine=machine, closed=closed, log_path=args.log)
        if impossible:
            rep["impossible_samples"] = output.rounded(impossible)
        output.write_json(os.path.join(out, "report.json"), rep)
        output.write_json(os.path.join(out, "model.json"), modelfile.build(prep, diag, log_path=args.log))
        machinejson.write(out, prep, diag, given, args.log, say, hinf_rule=args.hinf_weights == "rule")
        figs = []
        if not args.no_plots:
            for name, what, draw in FIGURES:
                draw(os.path.join(out, name), prep, diag)
                log.debug("figure %s", name)
                figs.append((name, what))
            if closed is not None:
                _plots().closed_loop(os.path.join(out, CLOSED_LOOP_FIGURE[0]), prep, sims)
                figs.append(CLOSED_LOOP_FIGURE)
        with open(os.path.join(out, "report.md"), "w", encoding="utf-8") as f:
            f.write(report.markdown(rep, figs))
        stage.commit()
    say(f"verdict: {rep['verdict']}; held-out relerr nominal {rep['nominal']['relerr_percent']:.4g} %, "
        f"extended {rep['extended']['relerr_percent']:.4g} %")
    if closed is not None:
        for name in ("nominal", "extended"):
            c = closed[name]
            say(f"closed loop ({name}): position {c['relerr_position_percent']:.3g} %, velocity "
                f"{c['relerr_velocity_percent']:.3g} %, force {c['relerr_force_percent']:.3g} %")
    say(f"wrote {args.out}/report.json, model.json, report.md" + (" and the figures" if figs else ""))
    return EXIT_OK


def cmd_validate(args):
    m = modelfile.load(args.model)
    lg = logreader.read_log(args.log)
    prep = signals.Prepared(lg, fc_hz=m.get("filter", {}).get("fc_hz", signals.FC_HZ))
    fit = modelfile.fit_of(m)
    w = prep.whole
    rel = fit.relerr(prep, w)
    if not math.isfinite(rel):
        raise ValueError(f"{args.model}: the model's prediction is not finite on this log")
    line = (f"{args.log}: relerr {rel:.4g} % over {w.stop - w.start} samples (the whole log) with "
            f"{args.model} ({' + '.join(m.get('causes', [])) or 'nominal'})")
    if "nominal_params" in m:
        line += f"; nominal model {model.from_params(m['nominal_params'], ()).relerr(prep, w):.4g} %"
    # the command's result: standard output, one line (messages go to the log on standard error)
    sys.stdout.write(line + "\n")
    return EXIT_OK


class _Format(logging.Formatter):
    """Progress as plain lines; warnings and errors prefixed with their level."""

    def format(self, record):
        msg = super().format(record)
        return msg if record.levelno < logging.WARNING else f"{record.levelname.lower()}: {msg}"


def setup_logging(level):
    """The package's logger "bristle" to standard error at level; replaces the
    handler of an earlier call (tests call main() repeatedly in one process,
    with standard error redirected)."""
    root = logging.getLogger("bristle")
    for h in list(root.handlers):
        if getattr(h, "_bristle_cli", False):
            root.removeHandler(h)
    h = logging.StreamHandler(sys.stderr)
    h._bristle_cli = True
    h.setFormatter(_Format("%(message)s"))
    root.addHandler(h)
    root.setLevel(level)
    root.propagate = False


def parser(prog="bristle-diagnose"):
    common = argparse.ArgumentParser(add_help=False)
    g = common.add_mutually_exclusive_group()
    g.add_argument("-q", "--quiet", action="store_true",
                   help="log only warnings and errors (no progress lines)")
    g.add_argument("-v", "--verbose", action="store_true",
                   help="log debug detail as well (files chosen, stage timings)")
    ap = argparse.ArgumentParser(prog=prog, epilog=EPILOG,
                                 description="Diagnosis of a measured ball-screw log: what the nominal LuGre model "
                                             "gets wrong, which cause explains it, and the extended model's gain "
                                             "(docs/diagnose.md).")
    ap.add_argument("--version", action="version", version=f"%(prog)s {__version__}",
                    help="print the version (the project's VERSION) and exit")
    sub = ap.add_subparsers(dest="cmd", required=True, metavar="COMMAND",
                            help="diagnose a log, or validate a saved model on another log")
    d = sub.add_parser("diagnose", parents=[common], epilog=EPILOG,
                       help="fit the nominal model, test the causes, write the report, model.json and machine.json",
                       description="Fit the nominal LuGre model to a measured log, test each cause, and write "
                                   "report.json, model.json, machine.json, report.md and the figures into --out.")
    d.add_argument("--log", required=True, metavar="CSV",
                   help="the measured log (../shared/spec/measured-log.md: t, pos, force columns)")
    d.add_argument("--out", required=True, metavar="DIR",
                   help="output directory, replaced as a whole when the run succeeds: new, empty, or a previous "
                        "diagnosis's (a folder holding other files is refused)")
    d.add_argument("--machine", metavar="JSON",
                   help="the log's controller file, or a firmware machine file (format 2) whose values "
                        "machine.json takes; default: <log>.machine.json beside the log, else a file of "
                        "bristle/diagnose/machines/ listing the log's name")
    d.add_argument("--fc", type=float, default=signals.FC_HZ, metavar="HZ",
                   help=f"low-pass cutoff of the velocity and acceleration filter, Hz (default {signals.FC_HZ:g})")
    d.add_argument("--no-plots", action="store_true", help="write no figures (no matplotlib needed)")
    d.add_argument("--hinf-weights", choices=("given", "rule"), default="given",
                   help="machine.json's control.hinf: the given (or reference) file's weights, replaced by the "
                        "weights from the machine where they admit no acceptable design (given, the default); "
                        "or the weights from the machine (rule; docs/modules/hinf.md, \"Weights from the machine\")")
    v = sub.add_parser("validate", parents=[common], epilog=EPILOG,
                       help="relerr of a saved model on another log",
                       description="The relative error of a saved model (model.json of a diagnosis) on another "
                                   "log of the same machine, over the whole log; one line on standard output.")
    v.add_argument("--model", required=True, metavar="JSON", help="model.json written by `diagnose`")
    v.add_argument("--log", required=True, metavar="CSV", help="another measured log of the same machine")
    return ap


def main(argv=None, prog="bristle-diagnose"):
    args = parser(prog).parse_args(argv)
    setup_logging(logging.WARNING if args.quiet else logging.DEBUG if args.verbose else logging.INFO)
    try:
        return cmd_diagnose(args) if args.cmd == "diagnose" else cmd_validate(args)
    except (logreader.LogError, closedloop.ControllerError) as e:
        log.error("%s", e)
    except ValueError as e:  # too few samples for the split, a singular fit
        log.error("%s: %s", args.log, e)
    except ArithmeticError as e:  # overflow, division by zero in degenerate data the guards let through
        log.error("%s: numerical failure (%s)", args.log, e)
    except OSError as e:  # writing the outputs
        log.error("%s: %s", e.filename or args.cmd, e.strerror)
    return EXIT_INPUT
