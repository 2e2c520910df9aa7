/* SPDX-License-Identifier: Apache-2.0 */
/* The scripted run of tests/rec/gen_rec_golden.py, in the firmware: what
 * test_rec_golden compares with the Python's bytes and br_rec_emit writes
 * for test_rec_golden.py. */
#ifndef BR_REC_GOLDEN_RUN_H
#define BR_REC_GOLDEN_RUN_H

#include "rec_support.h"

/* Telemetry at N = 1 sends each golden sample; the recorder (capacity the
 * samples, pre-trigger all but one) records them, a command trigger asked
 * before the last; a dump from 0 to its rec_end. The link's frames start at
 * BR_REC_GOLDEN_SEQ0; the bytes land in sink. BR_OK or the first error. */
br_status_t rec_golden_run(golden_sink_t *sink);

#endif
