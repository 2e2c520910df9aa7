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

#endif
