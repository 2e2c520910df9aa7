/* SPDX-License-Identifier: Apache-2.0 */
/* How a host tool reports one closed-loop run (docs/tools.md, "A faulted run
 * is not a result"). A run the firmware stopped (a latched fault: lost lock,
 * an encoder guard, ...) ended early: its RMS covers the periods before the
 * stop and is not comparable with a run that went to the end. So a faulted
 * run is printed and written as a fault, with its time and cause, and its
 * figures are null in the JSON; only a run that went to the end has them. */
#ifndef BR_RUN_REPORT_H
#define BR_RUN_REPORT_H

#include <stdio.h>

/* A run that went to the end with its table not following the reference (a
 * circle's table farther from the reference point than the radius: a
 * motionless axis sits on the circle with no radial error) is no result
 * either: the harness reports it as a fault of its own, status
 * BR_RUN_NOT_FOLLOWED, cause BR_RUN_CAUSE_NOT_FOLLOWED ("not_followed"),
 * outside the firmware's statuses and br_app_fault_t. */
#define BR_RUN_NOT_FOLLOWED (-1000)
#define BR_RUN_CAUSE_NOT_FOLLOWED (-1)

/* A run whose application the firmware refused at init (br_app_init or an
 * estimator's init returned a BR_E_* status: a setting out of range, the
 * estimation model's sub-step bound) never started: it is reported as a
 * fault at 0 s with that status and the cause BR_RUN_CAUSE_REFUSED_AT_INIT
 * ("refused_at_init"), so that it is counted, never a figure and never absent. */
#define BR_RUN_CAUSE_REFUSED_AT_INIT (-2)

typedef struct {
    double rms_m;   /* contour or tracking RMS over the run */
    double max_m;   /* largest error */
    int fault_status; /* 0: ran to the end; else the firmware's negative status (or BR_RUN_NOT_FOLLOWED) */
    int fault_cause;  /* br_app_fault_t of the latched fault (0 unknown) */
    double fault_t_s; /* when the firmware stopped the axis */
} br_run_report_t;

/* "lost_lock", "enc_jump", ...: the name of a br_app_fault_t (docs/reliability.md),
 * "unknown" for a value outside the enum. */
const char *br_run_fault_name(int cause);

/* One line: "<name> <what> RMS %.4e m, max %.4e m" for a run that went to the end,
 * "<name> FAULT at %.4f s (<cause>, status %d): no result" for a faulted one,
 * "<name> REFUSED at init (status %d): no result" for one refused at init. */
void br_run_print(FILE *f, const char *name, const char *what, const br_run_report_t *r);

/* The run's JSON members, without braces: "<rms_key>": x, "<max_key>": y, "faulted": false,
 * or "<rms_key>": null, "<max_key>": null, "faulted": true, "fault_status": s,
 * "fault_cause": "...", "fault_t_s": t. */
void br_run_json(FILE *f, const char *rms_key, const char *max_key, const br_run_report_t *r);

#endif
