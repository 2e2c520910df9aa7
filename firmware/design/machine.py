# SPDX-License-Identifier: Apache-2.0
"""Machine description (machines/*.json, format version 2): loader, validator
and the values derived from it. Documented field by field in
docs/machine-file.md; the reference machine is machines/reference.json.

    m = machine.load(path)        # validated, nested like the file; raises MachineError
    m = machine.load_or_exit(path)  # the same; on an error prints
                                    # "FILE: field a.b.c: problem" lines, exit status 1
    p = machine.params(m)         # the plant / eq. 6 parameters by their symbols
                                  # (L_mprad, Jeff_kgm2, rad_per_count, Fc_N, ...)

Run as a script it validates files: machine.py FILE... (exit 1 on any error)."""
import json
import math
import os
import re
import stat
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO_ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
# machines/ of the source tree; installed (pyproject.toml), the same folder is
# the package bristle.machines beside this file's bristle.design
MACHINES_DIR = os.path.join(REPO_ROOT, "machines")
if not os.path.isdir(MACHINES_DIR):
    MACHINES_DIR = os.path.join(HERE, "..", "machines")
REFERENCE_MACHINE = os.path.join(MACHINES_DIR, "reference.json")
# generated headers: one root on the include path, one folder per kind below bristle_gen/
GEN_DIR = os.path.join(REPO_ROOT, "firmware", "gen")

# the causes' registry (python/bristle/diagnose/causes/; installed, the package beside this one):
# the schema's "causes" follow it
_PY = os.path.join(REPO_ROOT, "python")
if os.path.isdir(_PY) and _PY not in sys.path:
    sys.path.insert(0, _PY)
from bristle.diagnose import causes as _causes  # noqa: E402

# the causes that are a force term of the estimators' extended model (a Maxwell-slip
# friction takes none of them yet), and those it combines with (the measurement side)
FORCE_CAUSES = tuple(m.NAME for m in _causes.of_hook("force"))
MSLIP_COMBINES = tuple(m.NAME for m in _causes.of_hook("measurement"))

FORMAT_VERSION = 2
# format 1 held the estimators' settings per step and in encoder counts; upgrade_machine.py converts it
FORMAT_UPGRADE = "python firmware/design/upgrade_machine.py OLD.json NEW.json"
# BR_PF_MAX_PARTICLES of firmware/include/bristle/br_pf.h
PF_MAX_PARTICLES = 2048
# BR_PF_MS_SLOTS of firmware/include/bristle/br_pf.h (its default, 4 BR_PF_MAX_PARTICLES): the
# Maxwell-slip element deflections the PF's particles carry, elements x particles at most
PF_MS_SLOTS_PER_PARTICLE = 4
PF_MS_SLOTS = PF_MS_SLOTS_PER_PARTICLE * PF_MAX_PARTICLES
# BR_EST_AHEAD_MAX_PERIODS of firmware/include/bristle/br_est.h
EST_AHEAD_MAX_PERIODS = 2.0
# BR_DLYID_MAX_CAND of firmware/include/bristle/br_dlyid.h
DLYID_MAX_CAND = 8
# BR_MSLIP_MAX of firmware/include/bristle/br_mslip.h: the most Maxwell-slip elements
MSLIP_MAX = 8
# |sum of the shares - 1| accepted; tighter than the firmware's BR_MSLIP_SHARE_TOL (1e-5, on
# float32 shares), so every file accepted here passes br_mslip_cfg_check
MSLIP_SHARE_TOL = 1.0e-6
# BR_EST_DELAY_HIST - 2 of firmware/include/bristle/br_est.h: the longest delay, in periods, an
# estimator's command history holds
EST_DELAY_MAX_PERIODS = 62
# the gate's transient factor k at most 10: ten of the largest single drops within one period
GATE_TRANSIENT_K_MAX = 10.0


class MachineError(Exception):
    """Every problem found in one file, one "FILE: field a.b.c: problem" line each."""

    def __init__(self, lines):
        super().__init__("\n".join(lines))
        self.lines = lines


# --- schema -----------------------------------------------------------------
# A leaf is Num / Int / Str; a section is a dict of name -> leaf or section.
# Bounds: lo / hi inclusive unless lo_open / hi_open.

class Num:
    def __init__(self, lo, hi, doc, lo_open=False, hi_open=False):
        self.lo, self.hi, self.doc, self.lo_open, self.hi_open = lo, hi, doc, lo_open, hi_open

    def range_text(self):
        return "%s%s, %s%s" % ("(" if self.lo_open else "[", _g(self.lo), _g(self.hi), ")" if self.hi_open else "]")

    def check(self, v):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            return None, "expected a number, got %s" % _kind(v)
        v = float(v)
        if not math.isfinite(v):
            return None, "not finite"
        below = v <= self.lo if self.lo_open else v < self.lo
        above = v >= self.hi if self.hi_open else v > self.hi
        if below or above:
            return None, "%s is outside %s" % (_g(v), self.range_text())
        return v, None


class Int(Num):
    def check(self, v):
        if isinstance(v, bool) or not isinstance(v, int):
            return None, "expected an integer, got %s" % _kind(v)
        if v < self.lo or v > self.hi:
            return None, "%d is outside %s" % (v, self.range_text())
        return v, None


class NumList(Num):
    """A list of n_lo..n_hi numbers, each in the range of Num."""

    def __init__(self, lo, hi, n_lo, n_hi, doc, lo_open=False, hi_open=False):
        super().__init__(lo, hi, doc, lo_open, hi_open)
        self.n_lo, self.n_hi = n_lo, n_hi

    def range_text(self):
        return "a list of %d to %d numbers in %s" % (self.n_lo, self.n_hi, super().range_text())

    def check(self, v):
        if not isinstance(v, list):
            return None, "expected a list of numbers, got %s" % _kind(v)
        if not self.n_lo <= len(v) <= self.n_hi:
            return None, "has %d entries, expected %d to %d" % (len(v), self.n_lo, self.n_hi)
        out, each = [], Num(self.lo, self.hi, self.doc, self.lo_open, self.hi_open)
        for i, e in enumerate(v):
            x, problem = each.check(e)
            if problem:
                return None, "entry %d: %s" % (i, problem)
            out.append(x)
        return out, None


class Str:
    def __init__(self, pattern, doc):
        self.pattern, self.doc = pattern, doc

    def range_text(self):
        return "text matching %s" % self.pattern

    def check(self, v):
        if not isinstance(v, str):
            return None, "expected a string, got %s" % _kind(v)
        if not re.fullmatch(self.pattern, v):
            return None, "%r does not match %s" % (v, self.pattern)
        return v, None


class Optional:
    """A section that may be left out (the causes: absent = the cause is off)."""

    def __init__(self, section):
        self.section = section


# where a value comes from (docs/machine-file.md, "provenance"); a field the
# block does not list is "given"
PROVENANCE_KINDS = ("identified", "derived", "assumed", "given")


class Provenance:
    """The optional "provenance" block: {"<field path>": one of PROVENANCE_KINDS};
    each path names a value (a leaf) of the file's schema."""

    def errors(self, value, path):
        if not isinstance(value, dict):
            return [(path, "expected an object, got %s" % _kind(value))]
        out = []
        for k, v in value.items():
            if not isinstance(_leaf(k), (Num, Str)):
                out.append((_join(path, k), "not a value of the machine file (a field path such as "
                                            "friction.Fc_N or causes.offset.offset_N)"))
            elif v not in PROVENANCE_KINDS:
                out.append((_join(path, k), "%r is not one of %s" % (v, ", ".join(PROVENANCE_KINDS))))
        return out


def _g(v):
    return "%g" % v if isinstance(v, float) else str(v)


def _kind(v):
    return {dict: "an object", list: "a list", str: "a string", bool: "a boolean",
            type(None): "null"}.get(type(v), type(v).__name__)


def _process_noise():
    """Process noise of x = [theta, omega, z, g_p], each a variance per second in
    units that hold across machines (docs/machine-file.md, "Estimator settings in
    physical units"); est_per_step() turns them into the per-step variances."""
    return {
        "theta_m2_per_s": Num(0.0, 1.0, "table position random walk, m^2 per second"),
        "force_Fs2_s": Num(0.0, 1.0e6, "unmodelled force on the table, white, its density in Fs^2 s "
                           "(Fs: friction.Fs_N): omega's process noise"),
        "z_zs2_per_s": Num(0.0, 1.0e9, "bristle deflection random walk, in zs^2 per second "
                           "(zs = Fs_N / sigma0_Npm, the deflection at breakaway)"),
        "gp_Fs2_per_s": Num(0.0, 1.0e9, "g_p random walk, in Fs^2 per second"),
    }


def _load_fields(what):
    """An external-force state's random walk (estimator.<est>.load): one of q_N2_per_s (N^2/s) or
    q_Fact2_per_s (in the actuator's force squared, per second: the form that holds on another axis);
    its initial variance and bound are the actuator's force (control.torque_limit_Nm / L), squared and
    itself (load_q_N2_per_s)"""
    return {
        "q_N2_per_s": Optional(Num(0.0, 1.0e9, "random walk of %s, variance per second (N^2/s)" % what,
                                   lo_open=True)),
        "q_Fact2_per_s": Optional(Num(0.0, 100.0, "random walk of %s, variance per second in the actuator's "
                                      "force squared (control.torque_limit_Nm / L)^2" % what, lo_open=True)),
    }


def _gates():
    return {
        "gp0_Fs": Num(0.0, 100.0, "initial g_p (the friction level the filter starts from), in Fs", lo_open=True),
        "gp_min_Fc": Num(0.0, 100.0, "g_p is kept >= this, in Fc (friction.Fc_N)", lo_open=True),
        "gp_max_Fs": Num(0.0, 100.0, "g_p is kept <= this, in Fs", lo_open=True),
        "position_noise_m2": Num(0.0, 1.0, "measurement noise of the position beyond the encoder's quantisation "
                                 "(interpolation and scale error, the model's position error over a period): "
                                 "R = 1/12 count^2 + this"),
        "outlier_gate_sigma": Num(0.0, 1.0e4, "a measurement further than this many standard deviations "
                                  "is an outlier", lo_open=True),
        "outlier_transient_k": Optional(Num(0.0, GATE_TRANSIENT_K_MAX,
                                            "the gate's transient term: a measurement is an outlier further "
                                            "than outlier_gate_sigma deviations plus k (Fs - Fc) T^2 / (2 Meff), "
                                            "the displacement a friction drop of Fs - Fc makes over the period "
                                            "(1: a drop at the period's start, the largest one drop makes; "
                                            "1/3: its mean); 0 or absent: the thesis gate")),
        "reanchor_after": Int(1, 1000, "consecutive outliers before the filter is re-anchored on the measurement "
                              "(a count: how unlikely that many in a row are by chance)"),
        "comp_ahead_periods": Num(0.0, EST_AHEAD_MAX_PERIODS, "0: compensate the filtered estimate (the thesis); "
                                  "> 0: the force predicted over the actuator delay and this many periods "
                                  "beyond it (docs/modules/est.md)"),
        # actuator-delay identification while the axis runs (docs/modules/dlyid.md); absent = off
        "delay_id": Optional({
            "candidates": Int(2, DLYID_MAX_CAND, "candidate delays 0, step_s, ..., (candidates - 1) step_s"),
            "step_s": Num(0.0, 0.1, "their spacing", lo_open=True),
            "q_force_Fs2_per_s": Num(0.0, 1.0e9, "the identifying filters' friction random walk, "
                                     "variance per second, in Fs^2", lo_open=True),
            "memory_s": Num(0.0, 100.0, "time constant of the innovations' forgotten sums", lo_open=True),
            "warmup_s": Num(0.0, 100.0, "no switch before this time after the first measurement"),
            "switch_ratio": Num(0.0, 1.0, "switch when the best candidate's sum is below this times the sum "
                                "of the delay in use", lo_open=True, hi_open=True),
            # a fast start, a slow steady state (docs/modules/dlyid.md); absent = one phase
            "steady": Optional({
                "after_s": Num(0.0, 100.0, "the steady phase from this time after the first measurement on",
                               lo_open=True),
                "memory_s": Num(0.0, 100.0, "its time constant of the forgotten sums", lo_open=True),
                "switch_ratio": Num(0.0, 1.0, "its switch ratio", lo_open=True, hi_open=True),
            }),
        }),
    }


SCHEMA = {
    "format_version": Int(FORMAT_VERSION, FORMAT_VERSION, "format of this file"),
    "name": Str(r"[a-z0-9][a-z0-9_-]*", "short name (file banners, build folders)"),
    "source": Str(r"(?s).*", "where the values come from"),
    "mechanics": {
        "table_mass_kg": Num(0.0, 1.0e4, "M, moving mass at the load", lo_open=True),
        "inertia_kgm2": Num(0.0, 1.0, "J, motor + screw inertia", lo_open=True),
        "lead_m_per_rev": Num(1.0e-4, 0.1, "ball-screw lead"),
    },
    "encoder": {
        "counts_per_rev": Int(4, 2**31, "counts per motor revolution"),
        "counter_bits": Int(16, 32, "width of the hardware counter (extended to 32 bits in software)"),
    },
    "amplifier": {
        "torque_per_duty_Nm": Num(0.0, 1.0e3, "motor torque at duty 1 (current mode)", lo_open=True),
        "duty_limit": Num(0.0, 1.0, "largest |duty| the amplifier accepts", lo_open=True),
    },
    "friction": {
        "sigma2_Nspm": Num(0.0, 1.0e6, "sigma2, viscous friction"),
        "sigma0_Npm": Num(0.0, 1.0e10, "LuGre bristle stiffness", lo_open=True),
        "sigma1_Nspm": Num(0.0, 1.0e8, "LuGre bristle damping"),
        "Fc_N": Num(0.0, 1.0e5, "Coulomb friction", lo_open=True),
        "Fs_N": Num(0.0, 1.0e5, "maximum stiction, >= Fc_N", lo_open=True),
        "vs_mps": Num(0.0, 1.0, "Stribeck velocity", lo_open=True),
    },
    # what a diagnosis of a measured log found beyond the nominal model (docs/diagnose.md);
    # grouped by cause, each parameter under its model.json name (the names of
    # br_causes_t and of br_plant_cfg_t too), each cause absent = off; from the
    # registry, each cause module's MACHINE (python/bristle/diagnose/causes/)
    "causes": {m.NAME: Optional({q.name: Num(*m.MACHINE[q.name]) for q in m.PARAMS})
               for m in _causes.REGISTRY if hasattr(m, "MACHINE")},
    # the estimators' friction model (docs/modules/mslip.md); absent = "lugre", the thesis model
    "friction_model": Optional({
        "model": Str(r"lugre|maxwell_slip", "the friction the estimators and the feedforward predict with: "
                     "lugre (eqs. 3-5, the thesis) or maxwell_slip (the clamp form of presliding.md)"),
        "breakaway_m": Optional(NumList(0.0, 1.0e-2, 1, MSLIP_MAX, "maxwell_slip: each element's breakaway "
                                        "displacement at Fs_N, d_i (k_i = share_i Fs_N / d_i)", lo_open=True)),
        "share": Optional(NumList(0.0, 1.0, 1, MSLIP_MAX, "maxwell_slip: each element's share of the "
                                  "Stribeck level, summing to 1", lo_open=True)),
    }),
    # the reversal (quadrant-error) compensation, the industrial baseline tuned from a circle test
    # (docs/modules/qec.md); absent = no pulse
    "reversal_comp": Optional({
        "A0_N": Num(0.0, 1.0e5, "pulse amplitude at zero acceleration of the reference"),
        "A1_kg": Num(-1.0e6, 1.0e6, "the amplitude's change per |reference acceleration|, N per m/s^2 "
                     "(the amplitude max(0, A0_N + A1_kg |a|))"),
        "tau_s": Num(0.0, 10.0, "the pulse's decay time constant (exponential)", lo_open=True),
    }),
    "control": {
        "period_s": Num(1.0e-5, 0.1, "control period (H-inf only, UKF)"),
        "estimator": Str(r"(pf|ukf|none)(,(pf|ukf|none))*", "the estimators the firmware image may run, in the "
                         "order of preference, comma-separated: the image runs the first its board can (pf in a loop "
                         "at estimator.pf.period_s, ukf or none at period_s; docs/configure.md)"),
        "torque_limit_Nm": Num(0.0, 1.0e3, "controller torque saturation, <= duty_limit * torque_per_duty_Nm; "
                               "also the H-inf design's torque scale (Dz = 1/torque_limit_Nm)", lo_open=True),
        "hinf": {
            "weight_theta_per_rad": Num(0.0, 1.0e6, "Cz weight on e_theta", lo_open=True),
            "weight_omega_s_per_rad": Num(0.0, 1.0e6, "Cz weight on e_omega"),
            "weight_eps_per_rad_s": Num(0.0, 1.0e6, "Cz weight on the integral eps", lo_open=True),
            "gamma_margin": Num(1.0, 100.0, "design gamma = gamma_margin * gamma_min", lo_open=True),
        },
    },
    "estimator": {
        "pf": dict({
            "period_s": Num(1.0e-5, 0.1, "the PF's (and its loop's) period"),
            "n_particles": Int(1, PF_MAX_PARTICLES, "particle count m"),
            "process_noise": _process_noise(),
            "x0_std": {
                "theta_m": Num(0.0, 1.0, "initial spread of theta around the first measurement beyond the "
                               "count's quantisation: std = sqrt(1/12 count^2 + theta_m^2)"),
                "speed_mps": Num(0.0, 100.0, "of the table speed around 0"),
                "z_zs": Num(0.0, 1.0e3, "of z around 0, in zs"),
                "gp_Fs": Num(0.0, 100.0, "of g_p around its initial value, in Fs"),
            },
            "noise_skip": Int(0, 1024, "extra ROM noise-table advance per step (docs/modules/pf.md)"),
            "adapt": {
                "nis_ref": Num(0.0, 1.0e6, "innovation-driven noise of omega, z and g_p: the smoothed NIS above which "
                               "it grows; 0 = off (the thesis filter; docs/modules/pf.md)"),
                "tau_s": Num(0.0, 100.0, "time constant of the NIS smoothing (per measured step "
                             "alpha = period_s / tau_s)", lo_open=True),
                "max_scale": Num(1.0, 1.0e12, "largest factor on the variances of omega, z and g_p"),
            },
            # g_p along the model's Stribeck curve (docs/modules/pf.md, "Fast moves"); absent = off,
            # g_p a random walk (the thesis)
            "gp_curve": Optional({
                "tau_s": Num(0.0, 100.0, "time constant of g_p's offset from the Stribeck curve g(v): "
                             "per step the offset is multiplied by exp(-period_s / tau_s)", lo_open=True),
            }),
            # the shared external force (docs/modules/pf.md, "External force"); absent = off,
            # the thesis filter
            "load": Optional(_load_fields("the shared external force F_d")),
        }, **_gates()),
        "ukf": dict({
            "process_noise": _process_noise(),
            "p0_var": {
                "theta_m2": Num(0.0, 1.0, "initial (and recovery) variance of theta beyond the count's "
                                "quantisation: 1/12 count^2 + this"),
                "speed_m2_per_s2": Num(0.0, 1.0e4, "of the table speed", lo_open=True),
                "z_zs2": Num(0.0, 1.0e6, "of z, in zs^2", lo_open=True),
                "gp_Fs2": Num(0.0, 1.0e4, "of g_p, in Fs^2", lo_open=True),
            },
            "alpha": Num(0.1, 1.0, "sigma-point spread"),
            "beta": Num(0.0, 10.0, "prior-distribution weight (2 for a Gaussian)"),
            "kappa": Num(-3.0, 100.0, "secondary scaling (n + kappa > 0, n = 4, 5 with load)", lo_open=True),
            # the external-force state (docs/modules/ukf.md, "External force"); absent = off,
            # the thesis's four states
            "load": Optional(_load_fields("the external force F_d")),
        }, **_gates()),
    },
    "limits": {
        "max_speed_mps": Num(0.0, 100.0, "largest table speed the axis is used at", lo_open=True),
        "travel_m": Num(0.0, 100.0, "stroke of the table, from travel_min_m", lo_open=True),
        "travel_min_m": Optional(Num(-100.0, 100.0, "position of the stroke's low end (position 0 is encoder "
                                     "count 0); without it the stroke is centred on 0, -travel_m / 2")),
        # the drive protections (docs/modules/app.md); a file without them
        # gets the defaults of limit_defaults()
        "max_accel_mps2": Optional(Num(0.0, 1000.0, "the reference limiter's and the braking ramp's acceleration",
                                       lo_open=True)),
        "max_following_error_m": Optional(Num(0.0, 1.0, "largest |reference - position| before the axis brakes",
                                              lo_open=True)),
        "coast_stop": Optional(Str(r"stroke|external", "where a stop with the outputs off (HAL, DEADLINE) ends: "
                                   "stroke (the default: the reference limiter caps the speed toward each end so "
                                   "that such a coast stops inside the stroke) or external (the machine's own "
                                   "end-of-travel protection takes it; no cap)")),
    },
    # where each value comes from (a diagnosis's machine.json writes it); optional
    "provenance": Optional(Provenance()),
}


def _leaf(dotted):
    """The schema leaf of a dotted field path, else None."""
    node = SCHEMA
    for k in dotted.split(".") if isinstance(dotted, str) else ():
        if isinstance(node, Optional):
            node = node.section
        if not isinstance(node, dict) or k not in node:
            return None
        node = node[k]
    if isinstance(node, Optional):
        node = node.section
    return node if isinstance(node, (Num, Str)) else None


def limit_defaults(m):
    """The drive limits of machine m, the file's or, where it leaves them out,
    the defaults: max_accel_mps2 half of what the actuator gives beyond
    stiction, (torque_limit / L - Fs) / (2 (M + J / L^2)); max_following_error_m
    what max_speed_mps covers in 10 ms."""
    lim, mech = m["limits"], m["mechanics"]
    L = mech["lead_m_per_rev"] / (2.0 * math.pi)
    mass = mech["table_mass_kg"] + mech["inertia_kgm2"] / (L * L)
    accel = (m["control"]["torque_limit_Nm"] / L - m["friction"]["Fs_N"]) / (2.0 * mass)
    lo = lim["travel_min_m"] if "travel_min_m" in lim else -0.5 * lim["travel_m"] if "travel_m" in lim else None
    return (lim.get("max_accel_mps2", accel), following_m(m), lo)


def following_m(m):
    """max_following_error_m of machine m, the file's or what max_speed_mps covers in 10 ms."""
    lim = m["limits"]
    return lim.get("max_following_error_m", 0.01 * lim["max_speed_mps"])


def stop_bound_m(m):
    """The stopping distance the soft travel limits keep from the stroke's
    ends (br_app_motion_cfg, docs/modules/app.md): a braking ramp (closed or
    open loop) from the speed fault's speed, max_speed (1 + SPEED_MARGIN), at
    max_accel, v^2 / (2 a), plus the period the fault is seen in, v period,
    plus the following error limit. The generated BR_MACHINE_STOP_BOUND_M;
    test_app holds the firmware's br_app_motion_cfg to it."""
    v = m["limits"]["max_speed_mps"] * (1.0 + SPEED_MARGIN)
    a = limit_defaults(m)[0]
    return v * v / (2.0 * a) + v * loop_period_s(m) + following_m(m)


def loop_period_s(m):
    """The longest period the application may run at: control.period_s, or
    the PF's when the machine runs the PF (the image's loop runs at it)."""
    return max(m["control"]["period_s"], m["estimator"]["pf"]["period_s"])


def coast_in_stroke(m):
    """1 when the reference limiter keeps a coast inside the stroke
    (limits.coast_stop "stroke", the default), 0 for "external"."""
    return 0 if m["limits"].get("coast_stop", "stroke") == "external" else 1


def coast_m(m):
    """How far the axis coasts from the speed fault's speed with the outputs
    off (the faults that cannot brake: HAL, DEADLINE), against Coulomb
    friction alone: v^2 (M + J / L^2) / (2 Fc). Kept inside the stroke by
    the reference limiter's coast envelope (limits.coast_stop "stroke") or by
    the machine's own end-of-travel protection ("external";
    docs/modules/app.md)."""
    mech = m["mechanics"]
    L = mech["lead_m_per_rev"] / (2.0 * math.pi)
    mass = mech["table_mass_kg"] + mech["inertia_kgm2"] / (L * L)
    v = m["limits"]["max_speed_mps"] * (1.0 + SPEED_MARGIN)
    return v * v * mass / (2.0 * m["friction"]["Fc_N"])


# the speed fault's margin over limits.max_speed_mps (BR_APP_SPEED_MARGIN)
SPEED_MARGIN = 0.2


def provenance(m, dotted):
    """Where the value at a dotted path comes from: the file's provenance
    block, "given" when it does not list the field."""
    return m.get("provenance", {}).get(dotted, "given")


def _walk(schema, value, path, errors):
    """Checks value against schema; returns the cleaned value (numbers as float / int)."""
    if isinstance(schema, Optional):
        schema = schema.section
    if isinstance(schema, Provenance):
        errors.extend(schema.errors(value, path))
        return dict(value) if isinstance(value, dict) else None
    if isinstance(schema, dict):
        if not isinstance(value, dict):
            errors.append((path, "expected an object, got %s" % _kind(value)))
            return None
        out = {}
        for k in value:
            if k not in schema:
                errors.append((_join(path, k), "unknown field (expected one of: %s)" % ", ".join(schema)))
        for k, sub in schema.items():
            if k not in value:
                if not isinstance(sub, Optional):
                    errors.append((_join(path, k), "missing"))
                continue
            out[k] = _walk(sub, value[k], _join(path, k), errors)
        return out
    v, problem = schema.check(value)
    if problem:
        errors.append((path, problem))
    return v


def _join(path, k):
    return k if not path else path + "." + k


def _cross_checks(m, errors):
    """Relations between fields (only when the fields themselves are valid)."""
    def get(dotted):
        v = m
        for k in dotted.split("."):
            if not isinstance(v, dict) or v.get(k) is None:
                return None
            v = v[k]
        return v

    def need(cond_fields, ok, field, problem):
        if all(get(f) is not None for f in cond_fields) and not ok():
            errors.append((field, problem))

    need(["friction.Fc_N", "friction.Fs_N"], lambda: get("friction.Fs_N") >= get("friction.Fc_N"),
         "friction.Fs_N", "must be >= friction.Fc_N (%s N)" % _g(get("friction.Fc_N") or 0.0))
    need(["control.torque_limit_Nm", "amplifier.duty_limit", "amplifier.torque_per_duty_Nm"],
         lambda: get("control.torque_limit_Nm") <= get("amplifier.duty_limit") * get("amplifier.torque_per_duty_Nm"),
         "control.torque_limit_Nm", "must be <= amplifier.duty_limit * amplifier.torque_per_duty_Nm")
    need(["control.estimator"],
         lambda: len(set(get("control.estimator").split(","))) == len(get("control.estimator").split(",")),
         "control.estimator", "names an estimator twice")
    for est in ("pf", "ukf"):
        e = "estimator.%s." % est
        lvl = ["friction.Fc_N", "friction.Fs_N"]
        need(lvl + [e + "gp_min_Fc", e + "gp_max_Fs"],
             lambda: get(e + "gp_min_Fc") * get("friction.Fc_N") < get(e + "gp_max_Fs") * get("friction.Fs_N"),
             e + "gp_max_Fs", "gp_max_Fs * Fs_N must be > %sgp_min_Fc * Fc_N" % e)
        need(lvl + [e + "gp_min_Fc", e + "gp_max_Fs", e + "gp0_Fs"],
             lambda: (get(e + "gp_min_Fc") * get("friction.Fc_N") <= get(e + "gp0_Fs") * get("friction.Fs_N")
                      <= get(e + "gp_max_Fs") * get("friction.Fs_N")),
             e + "gp0_Fs", "gp0_Fs * Fs_N must lie in [gp_min_Fc * Fc_N, gp_max_Fs * Fs_N]")
    need(["estimator.pf.adapt.tau_s", "estimator.pf.period_s"],
         lambda: get("estimator.pf.adapt.tau_s") >= get("estimator.pf.period_s"),
         "estimator.pf.adapt.tau_s", "must be >= estimator.pf.period_s (alpha = period_s / tau_s <= 1)")
    # the actuator delay within the command history the application's
    # stuck-encoder model keeps at the control period (br_app_init refuses more)
    need(["causes.actuator_delay.delay_s", "control.period_s"],
         lambda: get("causes.actuator_delay.delay_s") <= EST_DELAY_MAX_PERIODS * get("control.period_s"),
         "causes.actuator_delay.delay_s", "must be <= %d periods of control.period_s" % EST_DELAY_MAX_PERIODS)
    # each estimator's delay identification: its largest candidate within its command history
    for est, name in (("pf", "estimator.pf.period_s"), ("ukf", "control.period_s")):
        d = "estimator.%s.delay_id." % est
        need([d + "candidates", d + "step_s", name],
             lambda: (get(d + "candidates") - 1) * get(d + "step_s") <= EST_DELAY_MAX_PERIODS * get(name),
             d + "step_s", "(candidates - 1) * step_s must be <= %d periods of %s" % (EST_DELAY_MAX_PERIODS, name))
    need(["estimator.pf.adapt.nis_ref"],
         lambda: get("estimator.pf.adapt.nis_ref") == 0.0 or get("estimator.pf.adapt.nis_ref") >= 1.0e-6,
         "estimator.pf.adapt.nis_ref", "must be 0 (off) or >= 1e-6")
    # the drive's acceleration when the file leaves it out: the actuator must
    # give more than stiction
    if all(get(f) is not None for f in ("control.torque_limit_Nm", "friction.Fs_N", "mechanics.lead_m_per_rev",
                                        "limits.max_speed_mps")) and get("limits.max_accel_mps2") is None \
            and not limit_defaults(m)[0] > 0.0:
        errors.append(("limits.max_accel_mps2", "missing, and the default, half of what the actuator gives beyond "
                       "stiction, is not positive: control.torque_limit_Nm / L is below friction.Fs_N; give the "
                       "axis's acceleration"))
    # the soft travel limits (br_app_motion_cfg): the stroke less the stopping
    # distance at each end must leave travel, and fit the int32 position count
    elif all(get(f) is not None for f in ("limits.travel_m", "limits.max_speed_mps", "friction.Fc_N",
                                        "mechanics.lead_m_per_rev", "encoder.counts_per_rev")):
        _soft_limit_checks(m, errors)
    _friction_model_checks(get, errors)
    need(["encoder.counts_per_rev", "encoder.counter_bits"],
         lambda: get("encoder.counts_per_rev") <= 2 ** get("encoder.counter_bits"),
         "encoder.counts_per_rev", "more counts per revolution than the counter holds (2^counter_bits)")


def soft_limits_m(m):
    """The soft travel limits (lo, hi) of machine m in metres: the stroke
    [travel_min_m, travel_min_m + travel_m] less stop_bound_m at each end
    (br_app_motion_cfg)."""
    lo = limit_defaults(m)[2]
    b = stop_bound_m(m)
    return lo + b, lo + m["limits"]["travel_m"] - b


def _soft_limit_checks(m, errors):
    lo, hi = soft_limits_m(m)
    if not lo < hi:
        errors.append(("limits.travel_m", "%s m leaves no travel inside the soft limits: the axis needs %s m at "
                       "each end to brake from the speed fault's speed (docs/reliability.md, \"Drive protections\")"
                       % (_g(m["limits"]["travel_m"]), _g(stop_bound_m(m)))))
        return
    L = m["mechanics"]["lead_m_per_rev"] / (2.0 * math.pi)
    counts_per_m = m["encoder"]["counts_per_rev"] / (2.0 * math.pi * L)
    reach = max(abs(lo), abs(hi)) + following_m(m)
    if reach * counts_per_m >= 2.0 ** 31:
        errors.append(("limits.travel_m", "the stroke reaches %s m from position 0: %.4g counts, beyond the "
                       "int32 position count (2^31)" % (_g(reach), reach * counts_per_m)))
def _friction_model_checks(get, errors):
    """maxwell_slip needs its element set, lugre has none; the shares sum to 1."""
    model = get("friction_model.model")
    if model is None:
        return
    d, a = get("friction_model.breakaway_m"), get("friction_model.share")
    if model == "lugre":
        for f, v in (("breakaway_m", d), ("share", a)):
            if v is not None:
                errors.append(("friction_model." + f, "given with model lugre (only maxwell_slip has elements)"))
        return
    for f, v in (("breakaway_m", d), ("share", a)):
        if v is None:
            errors.append(("friction_model." + f, "missing (model maxwell_slip needs its element set)"))
    if d is None or a is None:
        return
    extra = sorted(c for c in (get("causes") or {}) if c in FORCE_CAUSES)
    if extra:
        errors.append(("friction_model.model", "maxwell_slip is not combined with the causes %s yet "
                       "(only %s; docs/modules/model.md)" % (", ".join(extra), ", ".join(MSLIP_COMBINES))))
    if len(d) != len(a):
        errors.append(("friction_model.share", "has %d entries, breakaway_m %d" % (len(a), len(d))))
    elif abs(math.fsum(a) - 1.0) > MSLIP_SHARE_TOL:
        errors.append(("friction_model.share", "sums to %.9g, must be 1 (within %g)" % (math.fsum(a), MSLIP_SHARE_TOL)))
    n_p = get("estimator.pf.n_particles")
    if isinstance(n_p, int) and n_p >= 1:
        lim = mslip_max(str(get("control.estimator") or ""), n_p)
        if len(d) > lim and lim < MSLIP_MAX:  # beyond MSLIP_MAX the list's own range says so
            errors.append(("friction_model.breakaway_m", "has %d elements; the PF's %d particles carry at most %d "
                           "(BR_PF_MS_SLOTS %d deflections: elements x estimator.pf.n_particles)"
                           % (len(d), n_p, lim, PF_MS_SLOTS)))


def mslip_max(estimators, n_particles):
    """The most Maxwell-slip elements a machine's estimators carry: MSLIP_MAX, and when the image
    may run the PF (pf in control.estimator, comma-separated) what its element storage holds at
    n_particles (BR_PF_MS_SLOTS)."""
    if "pf" not in estimators.split(","):
        return MSLIP_MAX
    return min(MSLIP_MAX, PF_MS_SLOTS // n_particles)


def mslip_elements(m):
    """The Maxwell-slip element set of the file as the firmware takes it:
    [(k_i N/m, share_i)], k_i = share_i Fs / d_i; [] for the LuGre model."""
    fm = m.get("friction_model") or {}
    if fm.get("model") != "maxwell_slip":
        return []
    Fs = m["friction"]["Fs_N"]
    return [(a * Fs / d, a) for d, a in zip(fm["breakaway_m"], fm["share"])]


def display_name(path):
    """The file as messages and banners name it: relative to the repository
    when it is inside, else as given."""
    a = os.path.abspath(path)
    return os.path.relpath(a, REPO_ROOT) if a.startswith(REPO_ROOT + os.sep) else path


def load(path=REFERENCE_MACHINE):
    """The validated machine description, nested like the file, plus "file"
    (its display name). Raises MachineError listing every problem."""
    name = display_name(path)
    try:
        # a device or a FIFO would block or never end: only a regular file is read
        if not stat.S_ISREG(os.stat(path).st_mode):
            raise MachineError(["%s: cannot read: not a regular file (a device, a FIFO or a folder)" % name])
        with open(path, "r", encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise MachineError(["%s: cannot read: %s" % (name, e.strerror or e)])
    try:
        raw = json.loads(text)
    except json.JSONDecodeError as e:
        raise MachineError(["%s: not valid JSON: line %d column %d: %s" % (name, e.lineno, e.colno, e.msg)])
    errors = []
    if isinstance(raw, dict) and "format_version" in raw and raw["format_version"] != FORMAT_VERSION:
        hint = ("; format 1's estimator settings were per step and in encoder counts: convert the file with "
                + FORMAT_UPGRADE) if raw["format_version"] == 1 else ""
        raise MachineError(["%s: field format_version: %r is not a version this loader reads (%d)%s"
                            % (name, raw["format_version"], FORMAT_VERSION, hint)])
    m = _walk(SCHEMA, raw, "", errors)
    if not errors:
        _cross_checks(m, errors)
    if not errors:
        _per_step_checks(m, errors)
    if errors:
        raise MachineError(["%s: field %s: %s" % (name, p or "(top level)", problem) for p, problem in errors])
    m["file"] = name
    return m


def load_or_exit(path=REFERENCE_MACHINE):
    """load(), for scripts: a bad file ends the program with its messages and exit status 1."""
    try:
        return load(path)
    except MachineError as e:
        for line in e.lines:
            sys.stderr.write(line + "\n")
        sys.exit(1)


def params(m):
    """The plant / estimation-model parameters by their symbols (thesis eqs.
    1-6), with the derived ones:
      L_mprad = lead / (2 pi),  Jeff_kgm2 = J + L^2 M,  rad_per_count = 2 pi / counts_per_rev."""
    mech, fr = m["mechanics"], m["friction"]
    p = {
        "lead_m_per_rev": mech["lead_m_per_rev"],
        "M_kg": mech["table_mass_kg"],
        "J_kgm2": mech["inertia_kgm2"],
        "sigma2_Nspm": fr["sigma2_Nspm"],
        "sigma0_Npm": fr["sigma0_Npm"],
        "sigma1_Nspm": fr["sigma1_Nspm"],
        "Fc_N": fr["Fc_N"],
        "Fs_N": fr["Fs_N"],
        "vs_mps": fr["vs_mps"],
        "counts_per_rev": float(m["encoder"]["counts_per_rev"]),
        "tau_per_duty_Nm": m["amplifier"]["torque_per_duty_Nm"],
    }
    p["L_mprad"] = p["lead_m_per_rev"] / (2.0 * math.pi)
    p["Jeff_kgm2"] = p["J_kgm2"] + p["L_mprad"] ** 2 * p["M_kg"]
    p["rad_per_count"] = 2.0 * math.pi / p["counts_per_rev"]
    return p



# --- the estimators' settings per step (docs/machine-file.md, "Estimator settings in physical units") ---
# The file states them per second, in metres, and relative to the machine's own
# friction levels, so that one set holds across machines; the firmware takes
# variances per step in its state's units (theta in rad; R, the initial spread
# and the recovery variance of theta in counts, multiplied by rad_per_count
# where the configuration is built: firmware/include/bristle/br_machine_cfg.h).
# With T the estimator's period, L = lead / 2 pi, Jeff = J + L^2 M, mpc = L
# rad_per_count (metres per count), zs = Fs / sigma0:
#   q_theta  = theta_m2_per_s T / L^2                       (rad^2; the PF: / mpc^2 in counts^2)
#   q_omega  = force_Fs2_s Fs^2 L^2 T / Jeff^2               (a white force on the table, eq. 6)
#   q_z      = z_zs2_per_s zs^2 T,   q_gp = gp_Fs2_per_s Fs^2 T
#   R        = 1/12 + max(position_noise_m2, ((d - zs)+ / 8)^2) / mpc^2
#                                                            (counts^2: the quantisation plus the rest)
#   with d = Fc T^2 / (2 Meff), Meff = Jeff / L^2: the friction transient's displacement over one
#   period (docs/fleet.md, "Holding on the fleet's axes"); the floor is 0 where d <= zs (the reference)
#   and at most R_COUNTS2_MAX
#   g_p      = gp0_Fs Fs in [gp_min_Fc Fc, gp_max_Fs Fs]
#   d_gate   = outlier_transient_k (Fs - Fc) T^2 / (2 Meff) / L  (rad: the outlier gate's transient term)
QUANT_COUNTS2 = 1.0 / 12.0  # variance of a uniform quantisation of one count
TRANSIENT_STD_SHARE = 1.0 / 8.0  # R's floor: the std of the position's prediction error, this share of
                                 # the friction transient beyond the bristles' zone (docs/fleet.md)
R_COUNTS2_MAX = 1.0e6       # the firmware's bound on R (br_est_cfg_check; _PER_STEP_BOUNDS)


def transient_m(m, est):
    """(d, zs): the friction transient's displacement over estimator est's period,
    d = Fc T^2 / (2 Meff) (how far a force error of Coulomb's size moves the axis in one
    period), and the bristles' zone zs = Fs / sigma0 (m)."""
    p, T, _, zs = _scales(m, est)
    meff = p["Jeff_kgm2"] / (p["L_mprad"] * p["L_mprad"])
    return p["Fc_N"] * T * T / (2.0 * meff), zs


MODEL_H = os.path.join(HERE, "..", "include", "bristle", "br_model.h")


def gate_transient_m(m, est):
    """The outlier gate's transient term of estimator est (eq. G1, docs/modules/pf.md,
    "The gate"): d = k (Fs - Fc) T^2 / (2 Meff), Meff = Jeff / L^2, k the file's
    outlier_transient_k (0 when absent): how far a friction drop of Fs - Fc at the
    start of the period moves the axis from the prediction by the period's end (m)."""
    p, T, _, _ = _scales(m, est)
    k = m["estimator"][est].get("outlier_transient_k", 0.0)
    meff = p["Jeff_kgm2"] / (p["L_mprad"] * p["L_mprad"])
    return k * (p["Fs_N"] - p["Fc_N"]) * T * T / (2.0 * meff)


def gate_transient_rad(m, est):
    """The gate's transient term as the firmware takes it (br_est_cfg_t.outlier_transient_rad):
    gate_transient_m / L, motor rad."""
    return gate_transient_m(m, est) / params(m)["L_mprad"]


def model_substep_bounds():
    """(BR_MODEL_SUB_RH_MAX, BR_MODEL_SUB_MAX) as firmware/include/bristle/br_model.h defines them"""
    with open(MODEL_H, encoding="utf-8") as f:
        h = f.read()
    return (float(re.search(r"#define BR_MODEL_SUB_RH_MAX ([0-9.eE+-]+)f", h).group(1)),
            int(re.search(r"#define BR_MODEL_SUB_MAX ([0-9]+)", h).group(1)))


def model_substeps(m, est):
    """(rho h, n): the estimation model's sub-steps at estimator est's period as
    br_model_init chooses them (docs/modules/model.md, "Sub-steps"; the
    bound BR_MODEL_SUB_RH_MAX read from firmware/include/bristle/br_model.h):
    rho the presliding mode's spectral radius, the largest |s| of
    s^2 + b s + wn^2 = 0 with wn^2 = sigma0 / Meff, b = (sigma1 + sigma2) / Meff
    (eq. S1), n = max(1, ceil(rho h / BR_MODEL_SUB_RH_MAX)) (eq. S2); (0, 1)
    with Maxwell-slip elements (the model keeps one step)."""
    if mslip_elements(m):
        return 0.0, 1
    c = model_substep_bounds()[0]
    p, T, _, _ = _scales(m, est)
    meff = p["Jeff_kgm2"] / (p["L_mprad"] * p["L_mprad"])
    wn = math.sqrt(p["sigma0_Npm"] / meff)
    b = (p["sigma1_Nspm"] + p["sigma2_Nspm"]) / meff
    rho = wn if b <= 2.0 * wn else 0.5 * (b + math.sqrt(b * b - 4.0 * wn * wn))
    return rho * T, max(1, math.ceil(rho * T / c))


def position_var_floor_m2(m, est):
    """The floor on the position's measurement variance beyond the quantisation: where the
    friction transient over a period d goes beyond the bristles' zone zs, the model's
    prediction over the period misses by up to d - zs (its bristle state cannot follow a
    reversal or a breakaway within the step), so the measurement model carries
    ((d - zs) TRANSIENT_STD_SHARE)^2; 0 where d <= zs."""
    d, zs = transient_m(m, est)
    return (max(0.0, d - zs) * TRANSIENT_STD_SHARE) ** 2


def _scales(m, est):
    p = params(m)
    T = m["estimator"]["pf"]["period_s"] if est == "pf" else m["control"]["period_s"]
    mpc = p["L_mprad"] * p["rad_per_count"]
    zs = p["Fs_N"] / p["sigma0_Npm"]
    return p, T, mpc, zs


def est_per_step(m, est):
    """Estimator est's ("pf" or "ukf") settings as the firmware takes them:
    {"q_theta_counts2" (PF) or "q_theta_rad2" (UKF), "q_omega_rad2ps2", "q_z_m2",
    "q_gp_N2", "r_counts2", "gp0_N", "gp_min_N", "gp_max_N", "dlyid_q_force_N2ps",
    and the PF's "x0_theta_counts", "x0_omega_radps", "x0_z_m", "x0_gp_N",
    "adapt_alpha", or the UKF's "p0_theta_counts2", "p0_omega_rad2ps2", "p0_z_m2",
    "p0_gp_N2"} (float64)."""
    p, T, mpc, zs = _scales(m, est)
    e = m["estimator"][est]
    L, Fs, Fc = p["L_mprad"], p["Fs_N"], p["Fc_N"]
    q = e["process_noise"]
    out = {
        "q_omega_rad2ps2": q["force_Fs2_s"] * Fs * Fs * L * L * T / (p["Jeff_kgm2"] * p["Jeff_kgm2"]),
        "q_z_m2": q["z_zs2_per_s"] * zs * zs * T,
        "q_gp_N2": q["gp_Fs2_per_s"] * Fs * Fs * T,
        "r_counts2": min(QUANT_COUNTS2 + max(e["position_noise_m2"], position_var_floor_m2(m, est)) / (mpc * mpc),
                         max(R_COUNTS2_MAX, QUANT_COUNTS2 + e["position_noise_m2"] / (mpc * mpc))),
        "gp0_N": e["gp0_Fs"] * Fs, "gp_min_N": e["gp_min_Fc"] * Fc, "gp_max_N": e["gp_max_Fs"] * Fs,
        "dlyid_q_force_N2ps": (e.get("delay_id") or {}).get("q_force_Fs2_per_s", 0.0) * Fs * Fs,
    }
    if est == "pf":
        x0 = e["x0_std"]
        out.update({
            "q_theta_counts2": q["theta_m2_per_s"] * T / (mpc * mpc),
            "x0_theta_counts": math.sqrt(QUANT_COUNTS2 + (x0["theta_m"] / mpc) ** 2),
            "x0_omega_radps": x0["speed_mps"] / L, "x0_z_m": x0["z_zs"] * zs, "x0_gp_N": x0["gp_Fs"] * Fs,
            "adapt_alpha": T / e["adapt"]["tau_s"],
        })
    else:
        p0 = e["p0_var"]
        out.update({
            "q_theta_rad2": q["theta_m2_per_s"] * T / (L * L),
            "p0_theta_counts2": QUANT_COUNTS2 + p0["theta_m2"] / (mpc * mpc),
            "p0_omega_rad2ps2": p0["speed_m2_per_s2"] / (L * L), "p0_z_m2": p0["z_zs2"] * zs * zs,
            "p0_gp_N2": p0["gp_Fs2"] * Fs * Fs,
        })

    return out


def _load_given(m, est):
    """(key, value) of the random walk estimator.<est>.load gives; None when the block is
    absent; ValueError unless exactly one of q_N2_per_s and q_Fact2_per_s is given."""
    ld = m["estimator"][est].get("load")
    if ld is None:
        return None
    given = [k for k in ("q_N2_per_s", "q_Fact2_per_s") if k in ld]
    if len(given) != 1:
        raise ValueError("needs exactly one of q_N2_per_s (N^2/s) and q_Fact2_per_s (the actuator's force "
                         "squared, per second)")
    return given[0], ld[given[0]]


def load_q_N2_per_s(m, est):
    """Estimator est's external-force random walk in N^2/s from its machine file's
    estimator.<est>.load: q_N2_per_s, or q_Fact2_per_s times the actuator's force squared;
    None when the block is absent; ValueError unless exactly one of the two is given."""
    given = _load_given(m, est)
    if given is None:
        return None
    key, q = given
    F_act = actuator_force_N(m)
    return q if key == "q_N2_per_s" else q * F_act * F_act


def load_field(m, est):
    """the field estimator.<est>.load's random walk is given by (for messages; a valid block)"""
    return "estimator.%s.load.%s" % (est, _load_given(m, est)[0])


def ukf_load(m):
    """The UKF's external-force state as the firmware takes it (br_ukf_load_t,
    docs/modules/ukf.md, "External force"): {"q_N2" per step (load_q_N2_per_s times
    control.period_s), "p0_N2" and "max_N" from the actuator's force
    control.torque_limit_Nm / L, squared and itself}; all 0 (off) when
    estimator.ukf.load is absent."""
    q = load_q_N2_per_s(m, "ukf")
    if q is None:
        return {"q_N2": 0.0, "p0_N2": 0.0, "max_N": 0.0}
    F_act = actuator_force_N(m)
    return {"q_N2": q * m["control"]["period_s"], "p0_N2": F_act * F_act, "max_N": F_act}


def pf_load_blockers(m):
    """Why machine m's PF cannot carry its shared external force (estimator.pf.load), one
    message each; [] when it can. br_pf_init refuses the load with the extended model (the
    cloud is moved and weighed again with eq. 6) and with Maxwell-slip elements (the move
    makes each particle's f_nl again from the LuGre state)."""
    why = []
    extended = sorted(c for c, v in m.get("causes", {}).items() if c in FORCE_CAUSES and any(v.values()))
    if extended:
        why.append("needs the thesis model; the causes %s make the estimators' model the extended one"
                   % ", ".join(extended))
    if (m.get("friction_model") or {}).get("model") == "maxwell_slip":
        why.append("needs the LuGre model; with friction_model maxwell_slip the PF's particles carry elements, "
                   "which the load's move of the cloud does not")
    return why


def actuator_force_N(m):
    """The actuator's force on the table, control.torque_limit_Nm / L (N): the
    external-force states' bound."""
    return m["control"]["torque_limit_Nm"] * 2.0 * math.pi / m["mechanics"]["lead_m_per_rev"]


def pf_load(m):
    """The PF's shared external force as the firmware takes it (br_pf_load_t,
    docs/modules/pf.md, "External force"): {"q_N2" per step (load_q_N2_per_s times
    estimator.pf.period_s), "max_N" the actuator's force}; None (off: the
    generated header leaves it out) when estimator.pf.load is absent."""
    q = load_q_N2_per_s(m, "pf")
    if q is None:
        return None
    return {"q_N2": q * m["estimator"]["pf"]["period_s"], "max_N": actuator_force_N(m)}


def pf_gp_curve_rho(m):
    """The PF's g_p-along-the-curve factor per step, rho = exp(-T / tau_s)
    (docs/modules/pf.md, "Fast moves"); 0 when estimator.pf.gp_curve is absent (off)."""
    e = m["estimator"]["pf"]
    return math.exp(-e["period_s"] / e["gp_curve"]["tau_s"]) if e.get("gp_curve") else 0.0


def est_physical(m, est, per_step):
    """The inverse of est_per_step for the values per_step holds: the machine
    file's fields (dotted paths under estimator.<est>.) that give them on
    machine m. Raises ValueError for a value the file cannot state (a variance
    of theta below the quantisation's)."""
    p, T, mpc, zs = _scales(m, est)
    L, Fs, Fc = p["L_mprad"], p["Fs_N"], p["Fc_N"]
    J2 = p["Jeff_kgm2"] * p["Jeff_kgm2"]

    def above_quant(v, name):
        if v < QUANT_COUNTS2:
            raise ValueError("%s %.6g count^2 is below the quantisation's 1/12 count^2" % (name, v))
        return (v - QUANT_COUNTS2) * mpc * mpc
    inv = {
        "q_theta_counts2": lambda v: v * mpc * mpc / T,
        "q_theta_rad2": lambda v: v * L * L / T,
        "q_omega_rad2ps2": lambda v: v * J2 / (Fs * Fs * L * L * T),
        "q_z_m2": lambda v: v / (zs * zs * T),
        "q_gp_N2": lambda v: v / (Fs * Fs * T),
        "r_counts2": lambda v: above_quant(v, "R"),
        "gp0_N": lambda v: v / Fs, "gp_min_N": lambda v: v / Fc,
        "gp_max_N": lambda v: v / Fs,
        "dlyid_q_force_N2ps": lambda v: v / (Fs * Fs),
        "x0_theta_counts": lambda v: math.sqrt(above_quant(v * v, "the initial variance")),
        "x0_omega_radps": lambda v: v * L, "x0_z_m": lambda v: v / zs,
        "x0_gp_N": lambda v: v / Fs, "adapt_alpha": lambda v: T / v,
        "p0_theta_counts2": lambda v: above_quant(v, "P0"),
        "p0_omega_rad2ps2": lambda v: v * L * L,
        "p0_z_m2": lambda v: v / (zs * zs), "p0_gp_N2": lambda v: v / (Fs * Fs),
    }
    return {PER_STEP_FIELD[k]: inv[k](v) for k, v in per_step.items()}


# the file's field (under estimator.<est>.) each per-step value comes from
PER_STEP_FIELD = {
    "q_theta_counts2": "process_noise.theta_m2_per_s", "q_theta_rad2": "process_noise.theta_m2_per_s",
    "q_omega_rad2ps2": "process_noise.force_Fs2_s", "q_z_m2": "process_noise.z_zs2_per_s",
    "q_gp_N2": "process_noise.gp_Fs2_per_s", "r_counts2": "position_noise_m2", "gp0_N": "gp0_Fs",
    "gp_min_N": "gp_min_Fc", "gp_max_N": "gp_max_Fs", "dlyid_q_force_N2ps": "delay_id.q_force_Fs2_per_s",
    "x0_theta_counts": "x0_std.theta_m", "x0_omega_radps": "x0_std.speed_mps", "x0_z_m": "x0_std.z_zs",
    "x0_gp_N": "x0_std.gp_Fs", "adapt_alpha": "adapt.tau_s", "p0_theta_counts2": "p0_var.theta_m2",
    "p0_omega_rad2ps2": "p0_var.speed_m2_per_s2", "p0_z_m2": "p0_var.z_zs2", "p0_gp_N2": "p0_var.gp_Fs2",
}


def _put(d, dotted, v):
    ks = dotted.split(".")
    for k in ks[:-1]:
        d = d.setdefault(k, {})
    d[ks[-1]] = v


def _get(d, dotted):
    for k in dotted.split("."):
        d = d[k]
    return d


def set_est_per_step(raw, est, per_step):
    """Writes into raw (a file's dict, its machine fields complete) the
    settings under estimator.<est> that give per_step's values, each with the
    fewest significant digits that give the same float32 per-step value on
    this machine (a readable file, the firmware's values unchanged). Returns
    the dotted fields written; raises ValueError when a value cannot be
    stated (est_physical) or does not come back."""
    e = raw["estimator"][est]
    phys = est_physical(raw, est, per_step)
    for field, v in phys.items():
        _put(e, field, v)
    for key, target in per_step.items():
        field = PER_STEP_FIELD[key]

        def same(r):
            _put(e, field, r)
            return float32(est_per_step(raw, est)[key]) == float32(target)
        full = _get(e, field)
        for digits in range(1, 18):
            if same(float("%.*g" % (digits, full))):
                break
        else:
            if not same(full):
                raise ValueError("estimator.%s.%s does not give %s back" % (est, field, key))
    return ["estimator.%s.%s" % (est, f) for f in phys]


def float32(v):
    """v rounded to the nearest float32 (as the generated _F literals are)."""
    return struct.unpack("f", struct.pack("f", v))[0]


# the firmware's bounds on the per-step values (br_est_cfg_check, br_pf_init, br_ukf_init):
# the per-step key, the file's field it comes from, lo, hi, 0 allowed
_PER_STEP_BOUNDS = {
    "pf": [("q_theta_counts2", "process_noise.theta_m2_per_s", 0.0, 1.0e6, True),
           ("x0_theta_counts", "x0_std.theta_m", 0.0, 1.0e6, True),
           ("x0_omega_radps", "x0_std.speed_mps", 0.0, 1.0e3, True),
           ("x0_z_m", "x0_std.z_zs", 0.0, 1.0e-3, True), ("x0_gp_N", "x0_std.gp_Fs", 0.0, 1.0e5, True)],
    "ukf": [("q_theta_rad2", "process_noise.theta_m2_per_s", 0.0, 1.0, True),
            ("p0_theta_counts2", "p0_var.theta_m2", 0.0, 1.0e6, False),
            ("p0_omega_rad2ps2", "p0_var.speed_m2_per_s2", 0.0, 1.0e6, False),
            ("p0_z_m2", "p0_var.z_zs2", 0.0, 1.0, False), ("p0_gp_N2", "p0_var.gp_Fs2", 0.0, 1.0e8, False),],
    "both": [("q_omega_rad2ps2", "process_noise.force_Fs2_s", 0.0, 1.0e3, True),
             ("q_z_m2", "process_noise.z_zs2_per_s", 0.0, 1.0e-6, True),
             ("q_gp_N2", "process_noise.gp_Fs2_per_s", 0.0, 1.0e6, True),
             ("r_counts2", "position_noise_m2", 0.0, 1.0e6, False),
             ("outlier_transient_counts", "outlier_transient_k", 0.0, 1.0e6, True)],
}
FLOAT32_MIN_NORMAL = 1.1754943508222875e-38


def _per_step_checks(m, errors):
    """Each per-step value within the firmware's bounds, a normal float32 (no
    subnormal) when not 0; a problem is named by the file's field it comes from."""
    bad = set()
    for est in ("pf", "ukf"):
        try:
            load_q_N2_per_s(m, est)
        except ValueError as e:
            errors.append(("estimator.%s.load" % est, str(e)))
            bad.add(est)
    if m["estimator"]["ukf"].get("load") and "ukf" not in bad:
        # br_ukf_init: q 0 or a normal float, P0 a normal float, both <= BR_EST_VAR_MAX
        ld = ukf_load(m)
        for key, x in (("q_N2", ld["q_N2"]), ("p0_N2", ld["p0_N2"])):
            if not FLOAT32_MIN_NORMAL <= x <= 1.0e12:
                errors.append((load_field(m, "ukf"), "gives %s = %.6g per step on this machine, "
                               "outside the firmware's (0 excluded) [%g, %g]" % (key, x, FLOAT32_MIN_NORMAL, 1.0e12)))
    pld = pf_load(m) if "pf" not in bad else None
    if pld:
        # br_pf_init: q a normal float <= BR_EST_VAR_MAX, 4 max_N^2 finite (max_N is the
        # actuator's force, bounded by the schema)
        if not FLOAT32_MIN_NORMAL <= pld["q_N2"] <= 1.0e12:
            errors.append((load_field(m, "pf"), "gives q_N2 = %.6g per step on this machine, "
                           "outside the firmware's (0 excluded) [%g, %g]" % (pld["q_N2"], FLOAT32_MIN_NORMAL, 1.0e12)))
        for why in pf_load_blockers(m):
            errors.append(("estimator.pf.load", why))
    for est in ("pf", "ukf"):
        v = est_per_step(m, est)
        # br_est_cfg_check bounds the gate's transient term in counts (BR_EST_GATE_MAX_TRANSIENT_COUNTS)
        v["outlier_transient_counts"] = gate_transient_rad(m, est) / params(m)["rad_per_count"]
        for key, field, lo, hi, zero_ok in _PER_STEP_BOUNDS[est] + _PER_STEP_BOUNDS["both"]:
            x = v[key]
            bad = (x == 0.0 and not zero_ok) or (x != 0.0 and not FLOAT32_MIN_NORMAL <= x <= hi) or x < lo
            if bad:
                errors.append(("estimator.%s.%s" % (est, field), "gives %s = %.6g per step on this machine, "
                               "outside the firmware's %s[%g, %g]" % (key, x, "" if zero_ok else "(0 excluded) ",
                                                                         lo, hi)))

# --- text that generated C embeds (docs/tools.md, "Inputs that cannot inject") ---
# A path or a field never goes into generated C as it is: into a comment only
# its c_comment_text() form, into a string only its c_string_literal().
_COMMENT_SAFE = re.compile(r"[A-Za-z0-9 ._+,:=@%~/-]")


def c_comment_text(s):
    """s for a C comment: every character outside [A-Za-z0-9 ._+,:=@%~/-]
    (quotes, backslashes, '*', '?', newlines, control and non-ASCII characters)
    replaced by '_', so it can neither end the comment ("*/"), splice a line
    ("\\", the trigraph "??/") nor start a new one."""
    return "".join(c if _COMMENT_SAFE.fullmatch(c) else "_" for c in s)


def c_string_literal(s):
    """s (UTF-8) as a C string literal, quotes included, that reads back as
    exactly its bytes: '"', '\\' and '?' (trigraphs) escaped, every byte
    outside printable ASCII as a three-digit octal escape."""
    out = []
    for b in s.encode("utf-8", "surrogateescape"):
        c = chr(b)
        if c in '"\\?':
            out.append("\\" + c)
        elif 0x20 <= b < 0x7F:
            out.append(c)
        else:
            out.append("\\%03o" % b)
    return '"' + "".join(out) + '"'


def write_atomic(path, text):
    """Writes text to path through a temporary file in its folder, renamed onto
    it only when the whole text is written: a failed generation leaves the old
    file as it was (and no temporary file)."""
    import tempfile
    d = os.path.dirname(os.path.abspath(path))
    os.makedirs(d, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".tmp-", dir=d)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def c_float(x):
    """A C float literal that round-trips exactly to the float32 nearest x."""
    import numpy as np
    f = np.float32(x)
    s = "%.9e" % float(f)
    assert np.float32(float(s)) == f
    return s + "f"


def main(argv):
    if not argv:
        sys.stderr.write("usage: machine.py FILE...  (validates machine descriptions)\n")
        return 2
    rc = 0
    for path in argv:
        try:
            load(path)
            print("%s: ok" % display_name(path))
        except MachineError as e:
            for line in e.lines:
                sys.stderr.write(line + "\n")
            rc = 1
    return rc


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
