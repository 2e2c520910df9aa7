# SPDX-License-Identifier: Apache-2.0
"""machine.json: the firmware machine file (firmware/design/machine.py, format 2) a
diagnosis writes beside model.json (docs/machine-file.md, "provenance";
docs/configure.md).

What a log identifies goes in from the extended model (model.json "params"
and "causes"), what it cannot identify (lead or encoder, amplifier, control
design, estimator settings, limits) from the given machine file (--machine,
when it is a machine file), else from machines/reference.json and
marked "assumed"; what follows from the log and the rest is "derived". The
"provenance" block lists every value that is not "given":

  mechanics        Meff_kg = J/L^2 + M split in the given file's proportion
                   (its inertia and mass both given), else J kept and
                   M = Meff - J/L^2 ("identified")
  encoder / lead   the log's position quantum is the encoder step at the load,
                   lead / counts_per_rev: with the counts given and the lead not,
                   the lead is derived; with the counts not given, the counts
  friction         params.NOMINAL's friction terms ("identified"), except what
                   the log cannot resolve: vs_mps below its velocity resolution
                   (quantum / dt), and with it Fs_N; sigma0_Npm whose presliding
                   length Fc/sigma0 is under 2 quanta, and with it sigma1_Nspm:
                   these keep the base's values ("assumed"; an assumed Fs_N
                   as the base's Fs/Fc times this Fc, the model's form)
  causes           model.json's causes and their parameters, same names ("identified")
  friction_model   presliding_hysteresis's element set as maxwell_slip ("identified"),
                   when the other causes are ones the estimators combine with it; with
                   more elements than the PF's particles carry (BR_PF_MS_SLOTS), the
                   closest smaller set ("derived", presliding_hysteresis.fewer_elements)
  control.hinf     the base's weights, unless they admit no acceptable H-inf design on
                   the identified machine, or hinf_rule asks, or they are derived (the
                   rule's for the base's friction): then the weights from the machine
                   for the identified one (firmware/design/hinf_weights.py, "derived")
  estimator        the base's, as they are (but estimator.pf.load where the PF cannot
                   carry it: a force cause or the Maxwell-slip elements found,
                   machine.pf_load_blockers): format 2 states them in the
                   machine's own units (per second, in metres, in Fs, Fc and
                   Fs/sigma0), so they follow the identified friction and
                   encoder by themselves (docs/machine-file.md); and when the
                   log identified the Stribeck curve and the base has no
                   estimator.pf.gp_curve, the PF's g_p along it ("derived")
"""
import copy
import importlib
import importlib.util
import math
import os
import re
import sys

import numpy as np

from . import causes as causes_
from . import closedloop, jsonfile, modelfile, output, params
from .logreader import LogError

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", ".."))
# presliding lengths shorter than this many position quanta are not resolved
PRESLIDING_MIN_QUANTA = 2.0
# the PF's g_p offset from an identified Stribeck curve relaxes with this time
# constant (docs/modules/pf.md, "Fast moves": measured 10 periods of 1.5 ms)
GP_CURVE_TAU_S = 0.015
# the causes the firmware's estimation model takes beside a Maxwell-slip friction
# (firmware/design/machine.py's friction_model check): the measurement-side ones
MSLIP_COMBINES = tuple(m.NAME for m in causes_.of_hook("measurement"))


def _loader():
    """firmware/design/machine.py, the one loader and schema of machine files;
    installed, the same file is bristle.design.machine (pyproject.toml)."""
    path = os.path.join(REPO, "firmware", "design", "machine.py")
    if not os.path.isfile(path):
        return importlib.import_module("bristle.design.machine")
    spec = importlib.util.spec_from_file_location("br_machine_loader", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def is_machine_file(path):
    """True when path is a machine file (it has "format_version"),
    not the diagnosis's controller file (python/bristle/diagnose/machines/)."""
    try:
        raw, _ = jsonfile.load(path)
    except LogError:
        return False  # machinefile.load names the problem
    return isinstance(raw, dict) and "format_version" in raw


def given(path):
    """path when it is a machine file, checked (ControllerError with
    the loader's "FILE: field ...: problem" lines when it is not valid); None
    when path is None or another file (the diagnosis's controller file)."""
    if path is None or not is_machine_file(path):
        return None
    mach = _loader()
    try:
        mach.load(path)
    except mach.MachineError as e:
        raise closedloop.ControllerError("\n".join(e.lines)) from None
    return path


def base(given=None):
    """The machine file a diagnosis starts from: the given one, else the reference machine."""
    mach = _loader()
    try:
        return mach.load(given or mach.REFERENCE_MACHINE)
    except mach.MachineError as e:
        raise closedloop.ControllerError("\n".join(e.lines)) from None


def _hinf_weights():
    """firmware/design/hinf_weights.py (with synth_hinf.py), or None where the source tree is not
    there (the installed package: `make firmware` checks the weights then)"""
    design = os.path.join(REPO, "firmware", "design")
    if not os.path.isfile(os.path.join(design, "hinf_weights.py")):
        return None
    if design not in sys.path:
        sys.path.insert(0, design)
    return importlib.import_module("hinf_weights")


def _hinf(m, prov, notes, always):
    """control.hinf: the base's weights when they give an acceptable design on m, else (or always,
    or when the base's weights are themselves derived: the rule's for the base's assumed friction)
    the weights from the machine (docs/modules/hinf.md, "Weights from the machine")"""
    hw = _hinf_weights()
    if hw is None:
        notes.append("control.hinf is not checked: firmware/design/hinf_weights.py is not here "
                     "(`make firmware` checks it)")
        return
    derived = all(prov.get("control.hinf." + k) == "derived" for k in m["control"]["hinf"])
    try:
        hinf, why = hw.weights_or_rule(m, always or derived, "asked for" if always else
                                       "the base's weights are derived: derived again on the identified machine")
    except hw.synth_hinf.DesignError as e:
        raise closedloop.ControllerError("control.hinf: %s" % e) from None
    if why is not None:
        m["control"]["hinf"] = hinf
        for k in hinf:
            prov["control.hinf." + k] = "derived"
        notes.append("control.hinf: %s" % why)


def _leaves(d, prefix=""):
    for k, v in d.items():
        path = prefix + k
        if isinstance(v, dict):
            yield from _leaves(v, path + ".")
        else:
            yield path


def encoder_step(pos):
    """The log's position step (closedloop.position_quantum), also when the
    printed positions carry a rounding error of their own: then the step is
    refined over the steps of up to 10 quanta, and the steps must be whole
    multiples of it within 2 % of a quantum. 0 when they are not (no encoder)."""
    q = closedloop.position_quantum(pos)
    if q > 0.0:
        return q
    d = np.abs(np.diff(pos))
    d = d[d > 0]
    if len(d) == 0:
        return 0.0
    n = np.round(d / d.min())
    small = n <= 10
    q = float(np.median(d[small] / n[small]))
    r = d / q
    return q if np.mean(np.abs(r - np.round(r)) < 0.02) > 0.95 else 0.0


def taken_from_file(diag):
    """The parameters machine.json takes from the machine file (identify.py):
    held in the model, or kept out of machine.json (non-physical, on a search
    bound, moved by a borderline cause)."""
    ident = getattr(diag, "identifiability", None) or {}
    return set(ident.get("held", {})) | set(ident.get("kept_out", {}))


def _set(m, dotted, value, prov, kind):
    *head, last = dotted.split(".")
    node = m
    for k in head:
        node = node.setdefault(k, {})
    node[last] = value
    prov[dotted] = kind


def build(prep, diag, given=None, log_path=None, hinf_rule=False):
    """The machine file as a dict (not yet rounded) and a list of notes; hinf_rule: the H-inf
    weights from the machine whatever the base's are."""
    mach = _loader()
    notes = []
    if given is not None:
        try:
            base = mach.load(given)
        except mach.MachineError as e:
            raise closedloop.ControllerError("\n".join(e.lines)) from None
        prov = {k: v for k, v in base.get("provenance", {}).items() if v != "given"}
    else:
        base = mach.load(mach.REFERENCE_MACHINE)
        prov = {}
        for path in _leaves({k: v for k, v in base.items()
                             if k not in ("format_version", "name", "source", "file", "causes", "provenance")}):
            prov[path] = "assumed"
    m = {k: copy.deepcopy(v) for k, v in base.items() if k not in ("file", "provenance")}
    kind = lambda path: prov.get(path, "given")  # noqa: E731
    p = diag.extended.params()

    # the log's position quantum: the encoder step at the load
    quantum = encoder_step(prep.pos)
    lead, cpr = m["mechanics"]["lead_m_per_rev"], m["encoder"]["counts_per_rev"]
    if quantum > 0.0:
        if kind("encoder.counts_per_rev") == "given" and kind("mechanics.lead_m_per_rev") != "given":
            _set(m, "mechanics.lead_m_per_rev", quantum * cpr, prov, "derived")
        elif kind("encoder.counts_per_rev") != "given":
            counts = int(round(lead / quantum))
            _set(m, "encoder.counts_per_rev", counts, prov, "derived")
        elif abs(lead / cpr - quantum) > 0.01 * quantum:
            notes.append("the log's position step %.4g m is not the given encoder step lead / counts_per_rev = "
                         "%.4g m" % (quantum, lead / cpr))
    L = m["mechanics"]["lead_m_per_rev"] / (2.0 * math.pi)

    # the moving mass at the load
    Meff = p["Meff_kg"]
    J, M = m["mechanics"]["inertia_kgm2"], m["mechanics"]["table_mass_kg"]
    from_file = taken_from_file(diag)
    if "Meff_kg" in from_file:
        notes.append("the moving mass is not taken from the log (report.json identifiability): the mechanics are the base's")
    elif kind("mechanics.inertia_kgm2") == "given" and kind("mechanics.table_mass_kg") == "given" and given:
        share = M / (J / L ** 2 + M)
        _set(m, "mechanics.table_mass_kg", share * Meff, prov, "identified")
        _set(m, "mechanics.inertia_kgm2", (1.0 - share) * Meff * L ** 2, prov, "identified")
    elif Meff - J / L ** 2 > 0.0:
        _set(m, "mechanics.table_mass_kg", Meff - J / L ** 2, prov, "identified")
    elif kind("mechanics.inertia_kgm2") != "given":
        # an axis lighter than the assumed screw's inertia alone: the
        # identified mass split in the assumed machine's proportion
        share = M / (J / L ** 2 + M)
        _set(m, "mechanics.table_mass_kg", share * Meff, prov, "identified")
        _set(m, "mechanics.inertia_kgm2", (1.0 - share) * Meff * L ** 2, prov, "identified")
        notes.append("the identified moving mass %.4g kg is below the assumed screw inertia's J/L^2 = %.4g kg: "
                     "split between table and screw in the assumed machine's proportion" % (Meff, J / L ** 2))
    else:
        raise closedloop.ControllerError(
            "%s: field mechanics.inertia_kgm2: J/L^2 = %.4g kg exceeds the identified moving mass Meff_kg = %.4g kg"
            % (given or mach.REFERENCE_MACHINE, J / L ** 2, Meff))

    # friction: what the log resolves is identified, the rest keeps the base's values
    fr = m["friction"]
    base_fr = dict(fr)
    v_res = quantum / prep.dt if quantum > 0.0 else 0.0
    unresolved = set()
    if p["vs_mps"] < v_res:
        unresolved |= {"vs_mps", "Fs_N"}
        notes.append("vs_mps %.3g m/s is below the log's velocity resolution %.3g m/s: vs_mps and Fs_N are not "
                     "identified" % (p["vs_mps"], v_res))
    if quantum > 0.0 and p["Fc_N"] / p["sigma0_Npm"] < PRESLIDING_MIN_QUANTA * quantum:
        unresolved |= {"sigma0_Npm", "sigma1_Nspm"}
        notes.append("the presliding length Fc/sigma0 %.3g m is under %g position steps: sigma0_Npm and "
                     "sigma1_Nspm are not identified" % (p["Fc_N"] / p["sigma0_Npm"], PRESLIDING_MIN_QUANTA))
    held = from_file
    unresolved |= held & set(fr)
    fs_given = kind("friction.Fs_N") == "given"  # a stiction the user measured stays as given
    for q in params.NOMINAL:
        if q.name not in fr:
            continue  # Meff_kg: above
        if q.name in held:
            pass  # the base's value, and its provenance (identify.py held it there)
        elif q.name in unresolved:
            prov["friction." + q.name] = "assumed"
        else:
            _set(m, "friction." + q.name, p[q.name], prov, "identified")
    # an Fs the log does not identify (held, kept out, below the velocity resolution) and the base
    # only assumes keeps the base's Stribeck ratio Fs/Fc at this Fc, as the model holds a held Fs
    # (beta: model.FIXED_SHAPE), not the base's Fs in N: the reference's 18 N was 46 times the
    # identified Fc of a fleet axis, a breakaway the estimators then expect and the axis never
    # shows (docs/fleet.md, "Why runs end worse than H-inf only"). sigma0 keeps the base's value:
    # its ratio to Fc gained nothing on the fleet and stiffened a 140 N axis's bristle into lost lock
    if ("Fs_N" in held or "Fs_N" in unresolved) and not fs_given:
        fr["Fs_N"] = base_fr["Fs_N"] * fr["Fc_N"] / base_fr["Fc_N"]
        notes.append("Fs_N %.4g N: the machine file's Fs/Fc %.4g (%.4g N / %.4g N) at this Fc %.4g N"
                     % (fr["Fs_N"], base_fr["Fs_N"] / base_fr["Fc_N"], base_fr["Fs_N"], base_fr["Fc_N"], fr["Fc_N"]))

    # the PF's g_p along the Stribeck curve (docs/modules/pf.md, "Fast moves"), when the log
    # identified the curve (Fs_N and vs_mps) and the base does not state it: without it g_p
    # is a random walk that cannot follow the drop from Fs to Fc as the axis breaks away
    pf = m["estimator"]["pf"]
    if "gp_curve" not in pf and not unresolved & {"vs_mps", "Fs_N"}:
        pf["gp_curve"] = {"tau_s": GP_CURVE_TAU_S}
        prov["estimator.pf.gp_curve.tau_s"] = "derived"

    # the causes, under the names of model.json (one table: the causes' PARAMS)
    base_causes = {"causes.%s.%s" % (c, k) for c, v in m.get("causes", {}).items() for k in v}
    m["causes"] = {}
    for c in causes_.of(diag.extended.causes):
        for q in c.PARAMS:
            # held at the machine file's value (identify.py): the base's, or assumed
            path = "causes.%s.%s" % (c.NAME, q.name)
            _set(m, path, p[q.name], prov, kind(path) if q.name in held and path in base_causes else
                 "assumed" if q.name in held else "identified")

    _friction_model(m, diag, prov, notes)
    _pf_load(m, notes)
    _hinf(m, prov, notes, hinf_rule)

    log_name = os.path.basename(log_path or prep.path)
    if given is None:
        m["name"] = re.sub(r"[^a-z0-9_-]+", "-", os.path.splitext(log_name)[0].lower()).strip("-_") or "machine"
        if not re.fullmatch(r"[a-z0-9][a-z0-9_-]*", m["name"]):
            m["name"] = "m" + m["name"]
    m["source"] = ("generated by python/bristle/diagnose (python -m bristle.diagnose), do not edit: the diagnosis "
                   "of %s on %s; provenance lists what the log identified, what is derived and what is assumed"
                   % (log_name, mach.display_name(given) if given else "no machine file (defaults of "
                      "machines/reference.json, assumed)"))
    m["provenance"] = {k: prov[k] for k in sorted(prov) if prov[k] != "given"}
    return m, notes


def _friction_model(m, diag, prov, notes):
    """presliding_hysteresis found: the element set as the estimators'
    Maxwell-slip friction (friction_model, docs/machine-file.md), which the
    firmware's estimation model combines with actuator_delay only (the
    loader's check): with another cause the file keeps LuGre, and says so."""
    ps = causes_.get(modelfile.PRESLIDING)
    others = sorted(c for c in m["causes"] if c not in MSLIP_COMBINES)
    if modelfile.PRESLIDING in diag.extended.causes:
        if others:
            m.pop("friction_model", None)
            notes.append("presliding_hysteresis: the element set is not written (friction_model): the firmware's "
                         "estimation model does not combine maxwell_slip with %s yet; model.json has it"
                         % ", ".join(others))
            return
        nl = diag.extended.nl
        # the PF's element storage (BR_PF_MS_SLOTS) binds when the image may run the PF
        n_max = _loader().mslip_max(m["control"]["estimator"], m["estimator"]["pf"]["n_particles"])
        d, a, err = ps.fewer_elements(nl["ps_breakaway"], nl["ps_share"], n_max)
        reduced = len(d) < len(nl["ps_share"])
        el = modelfile.presliding_elements(dict(nl, ps_breakaway=d, ps_share=a) if reduced else nl)
        m["friction_model"] = {"model": "maxwell_slip", "breakaway_m": el["breakaway_m"], "share": el["share"]}
        for f in ("model", "breakaway_m", "share"):
            prov["friction_model." + f] = "derived" if reduced else "identified"
        notes.append("presliding_hysteresis: friction_model maxwell_slip with %d elements, presliding_m %.3g m"
                     % (len(el["share"]), ps.presliding_m(el["breakaway_m"], el["share"])))
        if reduced:
            # the PF's element storage (BR_PF_MS_SLOTS) holds fewer at its particle count: the
            # closest smaller set (presliding_hysteresis.fewer_elements); model.json keeps the log's
            notes.append("presliding_hysteresis: the log's %d elements reduced to %d, the most the PF's %d "
                         "particles carry; the force-travel curve differs by at most %.3g %% of Fs_N "
                         "(model.json keeps the %d)" % (len(nl["ps_share"]), len(el["share"]),
                                                        m["estimator"]["pf"]["n_particles"], 100.0 * err,
                                                        len(nl["ps_share"])))
    elif (m.get("friction_model") or {}).get("model") == "maxwell_slip" and others:
        m.pop("friction_model")
        notes.append("the given friction_model maxwell_slip is dropped: the log shows %s, which the firmware's "
                     "estimation model does not combine with it yet" % ", ".join(others))


def _pf_load(m, notes):
    """The base's estimator.pf.load (the reference machine's among them) dropped where the
    diagnosed machine's PF cannot carry it (machine.pf_load_blockers: a force cause, the
    Maxwell-slip elements), and said so; the UKF's state stays."""
    if "load" not in m["estimator"]["pf"]:
        return
    why = _loader().pf_load_blockers(m)
    if why:
        del m["estimator"]["pf"]["load"]
        notes.append("the PF's shared external force (estimator.pf.load) is not written: it %s"
                     % "; it ".join(why))


def write(out_dir, prep, diag, given=None, log_path=None, say=print, hinf_rule=False):
    """Writes out_dir/machine.json and checks that it loads; returns its path."""
    m, notes = build(prep, diag, given=given, log_path=log_path, hinf_rule=hinf_rule)
    m = output.rounded(m)
    for f in ("counts_per_rev", "counter_bits"):
        m["encoder"][f] = int(m["encoder"][f])
    path = os.path.join(out_dir, "machine.json")
    output.write_json(path, m)
    mach = _loader()
    try:
        mach.load(path)
    except mach.MachineError as e:
        raise closedloop.ControllerError("the machine file written does not load:\n" + "\n".join(e.lines)) from None
    for n in notes:
        say("machine.json: " + n)
    kinds = {}
    for k, v in m["provenance"].items():
        kinds[v] = kinds.get(v, 0) + 1
    say("machine.json: %s" % ", ".join("%d %s" % (kinds[k], k) for k in sorted(kinds)))
    return path
