/* SPDX-License-Identifier: Apache-2.0 */
/* Shared helpers for the cmocka tests. */
#ifndef BR_TEST_H
#define BR_TEST_H

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

/* Fails with both values printed when |a - b| > tol (doubles). */
#define BR_ASSERT_NEAR(a, b, tol)                                                                 \
    do {                                                                                          \
        double br_a_ = (double)(a), br_b_ = (double)(b), br_t_ = (double)(tol);                    \
        if (!(fabs(br_a_ - br_b_) <= br_t_)) {                                                     \
            print_error("%s = %.9g, %s = %.9g, |diff| = %.3g > %.3g\n", #a, br_a_, #b, br_b_,      \
                        fabs(br_a_ - br_b_), br_t_);                                              \
            fail();                                                                               \
        }                                                                                         \
    } while (0)

/* Drive protections (bristle/br_app.h) that stay out of the way of the tests
 * of other guards: the tests' controller (L 1.27e-3 m/rad, 6e-6 rad per
 * count), a 120000-count step passes the limiter (1 m/s, 1000 m/s^2), 10 mm of
 * following error, a 10 m stroke centred on 0, a stiction band (2 x 1000 N) above the
 * actuator's force (no stuck-encoder fault), no coast envelope. */
#define BR_TEST_WIDE_MOTION                                                                       \
    br_app_motion_cfg(&(const br_app_machine_t){1.27e-3f, 6.0e-6f, 10.0f, 4e-5f, 7.0f, 1000.0f, 1.0f, 1000.0f, \
                                                0.01f, 10.0f, -5.0f, 1e-3f, 0, 0.0f})

#endif
