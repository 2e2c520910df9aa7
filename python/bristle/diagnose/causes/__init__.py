# SPDX-License-Identifier: Apache-2.0
"""The causes a diagnosis can name (../shared/spec/measured-log.md), one
module each, and their registry: REGISTRY is the ordered list the rest of
the package iterates (the order of the columns, of model.json's keys and of
the selection's tests). Adding a cause: a module here and a line in
REGISTRY (docs/diagnose.md, "Adding a cause").

What a cause module holds:

  NAME, MEANING        the spec's name; what it is physically (report.md)
  ACTION               what to check or do on the machine (report.md, with each finding)
  OPTION               br_simlog's / br_circle_ext's option that switches it on
                       (the C table sim/lib/plant/br_model_params.h)
  PARAMS               its model.json parameters (params.Param), in the
                       option's order; the same names as br_plant_cfg_t's fields
  NL                   the names of its nonlinear parameters in a fit's `nl`
  HOOK                 its kind of hook in the models (docs/architecture.md, "Adding a
                       cause"): "force" (a term of the load force: the firmware's
                       br_causes_t and its kernel term), "measurement" (what reaches the
                       axis or the log: the actuator delay) or "state" (states of its own:
                       the presliding element set, br_mslip_cfg_t)
  MACHINE              (force and measurement causes) the machine file's fields
                       (firmware/design/machine.py's "causes"): PARAMS name ->
                       (lo, hi, meaning[, lo_open]); their order is PARAMS', which is
                       br_causes_t's (firmware/design/gen_causes.py writes the C table)
  SWITCHES             (optional) the PARAMS whose value other than 0 switches the
                       cause on in the firmware (default: all of them)
  search(prep, base, fit_with) -> dict | None
                       its nonlinear parameters for base + it; fit_with(nl)
                       solves the linear ones with those (model.Fit, train_sse);
                       {} when it has none, None when the log cannot show it
  params(coef, nl, p), from_params(p) -> (coef, nl)
                       fit <-> model.json parameters (p: the nominal ones)
  report_params(p)     the parameters the spec names for a finding
  evidence(r, p)       one sentence from the nominal residual (evidence.Residual)
                       and the report parameters
  closed_loop(p, plant)
                       its terms in the closed-loop re-simulation's plant
                       (closedloop.Plant)

and, for the force model (model.py), the hooks it needs of:

  load_columns(prep, nl) -> dict      columns added to the force (linear coefficients)
  friction_scale(prep, nl) -> array   a factor on the friction (viscous + LuGre) over the intervals
  stribeck_neg_ratio(nl) -> float     the Stribeck curve's scale in -x, inside the bristle dynamics
  friction_columns(prep, nl, v, phi) -> dict
                                      the viscous and LuGre-level columns, replacing the nominal ones
  target(prep, nl) -> array           the force the model is compared with, replacing the filtered log's
  presliding_phi(prep, shape, ratio, nl) -> dict
                                      the friction level column(s), replacing the LuGre bristle's (and sigma1's)
  adjust_nominal(p, nl)               its effect on the nominal parameters it reports (sigma0 of an element set)
  report_nl(nl) -> dict               report parameters from its nonlinear ones (an element set: a list)

and FIGURES, ((file, what, function(path, prep, diag)), ...), if it draws any.

The studies (sim/studies/) take a cause that has their setting:

  DETECTION            detection_limits.py: (size name, unit, smallest size of the ladder,
                       flags(s, ref)), br_simlog's options for an effect of size s
                       (ref: the reference machine's Fc_N and sigma2_Nspm)
  robustness_draw(c, sgn) -> dict
                       robustness.py: the plant's parameters of the cause from
                       three uniforms c and a sign
  CONTROL_CASE         diagnose_control.py: (br_simlog / br_circle_ext flags, what they stand for)
"""
from .. import params
from . import (actuator_delay, asymmetric_friction, friction_drift, offset, position_gradient, position_ripple,
               presliding_hysteresis)

REGISTRY = (
    offset,
    asymmetric_friction,
    position_ripple,
    position_gradient,
    actuator_delay,
    friction_drift,
    presliding_hysteresis,
)

NAMES = tuple(m.NAME for m in REGISTRY)
# every model.json parameter: the nominal ones, then each cause's
MODEL_PARAMS = params.NOMINAL + tuple(q for m in REGISTRY for q in m.PARAMS)
_BY_NAME = {m.NAME: m for m in REGISTRY}


def get(name):
    return _BY_NAME[name]


def of(names):
    """The modules of the named causes, in registry order."""
    return tuple(m for m in REGISTRY if m.NAME in names)


def present(p):
    """The modules with parameters, every one of which p (model.json "params") holds."""
    return tuple(m for m in REGISTRY if m.PARAMS and all(q.name in p for q in m.PARAMS))


def of_hook(kind):
    """The modules whose HOOK is kind ("force", "measurement", "state"), in order."""
    return tuple(m for m in REGISTRY if m.HOOK == kind)


def firmware_params():
    """The causes' parameters the firmware's br_causes_t holds, in its order:
    (module, Param) of every force and measurement cause."""
    return tuple((m, q) for m in REGISTRY if m.HOOK in ("force", "measurement") for q in m.PARAMS)


def hooks(mods, name):
    """The hook `name` of each module that has it, in order."""
    return [getattr(m, name) for m in mods if hasattr(m, name)]
