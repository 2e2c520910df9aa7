/* SPDX-License-Identifier: Apache-2.0 */
/* Status codes shared by every bristle module: BR_OK is zero, a warning is
 * positive (the step succeeded and its outputs are valid), an error is
 * negative (the step failed; what was kept is said where it is returned). So
 * `st < 0` is the one test for failure everywhere. */
#ifndef BR_STATUS_H
#define BR_STATUS_H

typedef enum {
    BR_OK = 0,
    BR_W_OUTLIER = 1,  /* warning: the measurement was inconsistent with the whole estimate and
                          skipped; the step predicted only, its estimate is valid */
    BR_E_NULL = -1,    /* a required pointer is NULL */
    BR_E_PARAM = -2,   /* configuration value non-finite or out of range */
    BR_E_INPUT = -3,   /* step input non-finite or out of range */
    BR_E_NUMERIC = -4, /* the result would be non-finite; the state was kept */
    BR_E_STATE = -5,   /* module used before a successful init */
    BR_E_FAULT = -6,   /* latched: outputs off until re-armed (br_app_arm); the cause is kept
                          where it is returned (br_app_t.fault) */
    BR_E_BUSY = -7     /* no room now (br_link_send: the transmit buffer is full); nothing was
                          queued, the call may be repeated later */
} br_status_t;

/* 1 when st reports a failure (an error), 0 for BR_OK and for warnings. */
#define BR_FAILED(st) ((st) < 0)

#endif
