/* The thesis's X-Y circle experiment (section 5) on the simulator: two
 * identical axes, each a plant + host HAL + firmware control loop, tracking
 * x_ref = A sin(2 pi t / T), y_ref = A cos(2 pi t / T). */
#ifndef BR_CIRCLE_H
#define BR_CIRCLE_H

#include <stdio.h>

#include "bristle/br_ctrl.h"
#include "plant/br_sim_plant.h"

typedef enum { BR_CTRL_HINF_ONLY = 0 } br_circle_ctrl_t;

typedef struct {
    double radius_m;     /* A */
    double period_s;     /* T */
    double duration_s;
    double dt_s;         /* control period */
    br_circle_ctrl_t controller;
    br_plant_cfg_t plant; /* both axes alike */
    float K[3];          /* state-feedback gains */
} br_circle_cfg_t;

typedef struct {
    double contour_rms_m;   /* RMS of the radial (contour) error */
    double max_err_m;       /* max |radial error| */
    long n_samples;
    int saturated_steps;    /* periods where either axis saturated */
} br_circle_result_t;

/* The thesis experiment with the reference machine and the H-inf gains. */
br_circle_cfg_t br_circle_cfg_thesis(void);

/* Runs the experiment. If trace is not NULL, writes one CSV row per period:
 * t,x_ref,y_ref,x,y,radial_err,duty_x,duty_y,fnl_x,fnl_y. Returns 0, or -1
 * with a message on stderr on an invalid configuration or a firmware error. */
int br_circle_run(const br_circle_cfg_t *cfg, FILE *trace, br_circle_result_t *res);

#endif
