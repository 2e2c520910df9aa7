/* SPDX-License-Identifier: Apache-2.0 */
/* The parameters of a saved model, model.json's "params" (docs/diagnose.md,
 * "Parameters"): the one table of their names in C. The model loader
 * (br_plant_json.c) reads them by it, the simulators' cause options
 * (sim/lib/cause_args/br_cause_args.c) set them by it, and br_causes_from_model
 * copies the causes' rows into the firmware's extended estimation model
 * (br_causes_t, the same field names). The diagnosis (python/bristle/diagnose: params.py, one
 * module per cause in causes/) uses the same names, units and causes;
 * tests/diagnose/test_model.py holds the two tables together.
 *
 * A json name is the name of the br_plant_cfg_t field it sets, except
 * Meff_kg: the moving mass at the load, J/L^2 + M (a log cannot tell the
 * screw's inertia from the table's mass), which the loader splits between
 * J_kgm2 and M_kg in the base machine's proportion.
 *
 * Bounds: a value outside [lower, upper] is refused where it is read (file
 * and line, or option); BR_GT0 as the lower bound means "> 0". The upper
 * bounds are physical (a ball-screw axis at the load: 10 t, 100 kN, 10 m/s)
 * with decades of margin; they keep every product of the simulation and the
 * fit finite. The diagnosis's table (python/bristle/diagnose/params.py and
 * causes/) holds the same bounds; test_model.py compares them. Relations
 * between fields (Fs_N >= Fc_N, Fc_N + dFc_neg_N > 0, ...) are
 * br_plant_init's. */
#ifndef BR_MODEL_PARAMS_H
#define BR_MODEL_PARAMS_H

#include <float.h>
#include <math.h>
#include <stdio.h>

#include "br_sim_plant.h"
#include "bristle/br_model.h"

#define BR_GT0 DBL_MIN

/* X(json name, token, unit, lower, upper): the moving mass (required) */
#define BR_MEFF_PARAM(X) X("Meff_kg", Meff_kg, "kg", BR_GT0, 1e4)

/* X(json name, br_plant_cfg_t field, unit, lower, upper): the nominal
 * (thesis) model, load side (required) */
#define BR_NOMINAL_PARAMS(X)                                   \
    X("sigma2_Nspm", sigma2_Nspm, "N s/m", 0.0, 1e6)          \
    X("Fc_N", Fc_N, "N", BR_GT0, 1e5)                         \
    X("Fs_N", Fs_N, "N", BR_GT0, 1e5)                         \
    X("vs_mps", vs_mps, "m/s", BR_GT0, 10.0)                  \
    X("sigma0_Npm", sigma0_Npm, "N/m", BR_GT0, 1e12)          \
    X("sigma1_Nspm", sigma1_Nspm, "N s/m", 0.0, 1e8)

/* X(json name, br_plant_cfg_t field, unit, lower, upper, cause, option,
 *   required): the causes (optional; absent = 0 = off). `option` is the
 * simulators' command-line option that sets the cause's rows, its values in
 * the rows' order; `required` 0: may be left out of the option (then 0), only
 * after the required ones. */
#define BR_CAUSE_PARAMS(X)                                                                                 \
    X("offset_N", offset_N, "N", -1e5, 1e5, "offset", "--offset", 1)                                       \
    X("dFc_neg_N", dFc_neg_N, "N", -1e5, 1e5, "asymmetric_friction", "--asym", 1)                          \
    X("dsigma2_neg_Nspm", dsigma2_neg_Nspm, "N s/m", -1e6, 1e6, "asymmetric_friction", "--asym", 1)        \
    X("ripple_amp_N", ripple_amp_N, "N", -1e5, 1e5, "position_ripple", "--ripple", 1)                      \
    X("ripple_period_m", ripple_period_m, "m", BR_GT0, 10.0, "position_ripple", "--ripple", 1)             \
    X("ripple_phase_rad", ripple_phase_rad, "rad", -1e3, 1e3, "position_ripple", "--ripple", 0)            \
    X("grad_per_m", grad_per_m, "1/m", -1e3, 1e3, "position_gradient", "--gradient", 1)                    \
    X("delay_s", delay_s, "s", 0.0, BR_PLANT_DELAY_MAX_S, "actuator_delay", "--delay", 1)                \
    X("drift_per_s", drift_per_s, "1/s", -1.0, 1.0, "friction_drift", "--drift", 1)

/* The causes of a model (a diagnosis's model.json, loaded into a plant
 * configuration) for the firmware's extended estimation model: br_causes_t
 * has the same fields, one per row of BR_CAUSE_PARAMS. */
static inline br_causes_t br_causes_from_model(const br_plant_cfg_t *p)
{
    br_causes_t c = {0};
#define BR_CAUSE_COPY(json, field, unit, lo, hi, cause, option, req) c.field = (float)p->field;
    BR_CAUSE_PARAMS(BR_CAUSE_COPY)
#undef BR_CAUSE_COPY
    return c;
}

/* 1 when v is within [lo, hi] (NaN is not) */
static inline int br_param_in_bounds(double v, double lo, double hi)
{
    return v >= lo && v <= hi;
}

/* "must be > 0", "must be >= 0", "must be in a .. b", ... into buf */
static inline void br_param_bounds_text(double lo, double hi, char *buf, size_t n)
{
    if (lo == BR_GT0 && hi != HUGE_VAL) {
        snprintf(buf, n, "must be > 0 and <= %g", hi);
    } else if (hi == HUGE_VAL) {
        if (lo == BR_GT0) snprintf(buf, n, "must be > 0");
        else if (lo == -HUGE_VAL) snprintf(buf, n, "must be finite");
        else snprintf(buf, n, "must be >= %g", lo);
    } else if (lo == -HUGE_VAL) {
        snprintf(buf, n, "must be <= %g", hi);
    } else {
        snprintf(buf, n, "must be in %g .. %g", lo, hi);
    }
}

#endif
