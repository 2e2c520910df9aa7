/* SPDX-License-Identifier: Apache-2.0 */
/* A closed-loop run's report: a faulted run is a fault, never an RMS (br_run_report.h). */
#include "tool/br_run_report.h"

#include "bristle/br_app.h"

const char *br_run_fault_name(int cause)
{
    switch (cause) {
    case BR_APP_FAULT_NONE: return "none";
    case BR_APP_FAULT_DISARMED: return "disarmed";
    case BR_APP_FAULT_CTRL_INPUT: return "ctrl_input";
    case BR_APP_FAULT_CTRL_STATE: return "ctrl_state";
    case BR_APP_FAULT_ESTIMATOR: return "estimator";
    case BR_APP_FAULT_ENC_JUMP: return "enc_jump";
    case BR_APP_FAULT_ENC_STALE: return "enc_stale";
    case BR_APP_FAULT_ENC_FROZEN: return "enc_frozen";
    case BR_APP_FAULT_DEADLINE: return "deadline";
    case BR_APP_FAULT_HAL: return "hal";
    case BR_APP_FAULT_LOST_LOCK: return "lost_lock";
    case BR_APP_FAULT_SPEED: return "speed";
    case BR_APP_FAULT_FOLLOWING: return "following";
    case BR_APP_FAULT_TRAVEL: return "travel";
    case BR_APP_FAULT_REF_UNDERRUN: return "ref_underrun";
    case BR_RUN_CAUSE_NOT_FOLLOWED: return "not_followed";
    case BR_RUN_CAUSE_REFUSED_AT_INIT: return "refused_at_init";
    default: return "unknown";
    }
}

void br_run_print(FILE *f, const char *name, const char *what, const br_run_report_t *r)
{
    if (r->fault_status != 0 && r->fault_cause == BR_RUN_CAUSE_REFUSED_AT_INIT) {
        fprintf(f, "%-14s REFUSED at init (status %d): no result\n", name, r->fault_status);
    } else if (r->fault_status != 0) {
        fprintf(f, "%-14s FAULT at %.4f s (%s, status %d): no result\n", name, r->fault_t_s,
                br_run_fault_name(r->fault_cause), r->fault_status);
    } else {
        fprintf(f, "%-14s %s RMS %.4e m, max %.4e m\n", name, what, r->rms_m, r->max_m);
    }
}

void br_run_json(FILE *f, const char *rms_key, const char *max_key, const br_run_report_t *r)
{
    if (r->fault_status != 0) {
        fprintf(f, "\"%s\": null, \"%s\": null, \"faulted\": true, \"fault_status\": %d, \"fault_cause\": \"%s\", "
                   "\"fault_t_s\": %.6g",
                rms_key, max_key, r->fault_status, br_run_fault_name(r->fault_cause), r->fault_t_s);
    } else {
        fprintf(f, "\"%s\": %.6e, \"%s\": %.6e, \"faulted\": false, \"fault_status\": 0", rms_key, r->rms_m, max_key,
                r->max_m);
    }
}
