/* Status codes shared by every bristle module. BR_OK is zero, errors are negative. */
#ifndef BR_STATUS_H
#define BR_STATUS_H

typedef enum {
    BR_OK = 0,
    BR_E_NULL = -1,    /* a required pointer is NULL */
    BR_E_PARAM = -2,   /* configuration value non-finite or out of range */
    BR_E_INPUT = -3,   /* step input non-finite or out of range */
    BR_E_NUMERIC = -4, /* the result would be non-finite; the state was kept */
    BR_E_STATE = -5,   /* module used before a successful init */
    BR_E_OUTLIER = -6  /* measurement inconsistent with the whole estimate; update skipped */
} br_status_t;

#endif
