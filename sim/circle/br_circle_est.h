/* Estimator configurations for the circle experiment on the reference machine. */
#ifndef BR_CIRCLE_EST_H
#define BR_CIRCLE_EST_H

#include "bristle/br_pf.h"

/* The PF of thesis section 5 (1500 particles) at period dt_s. */
br_pf_cfg_t br_circle_pf_cfg_default(float dt_s);

#endif
