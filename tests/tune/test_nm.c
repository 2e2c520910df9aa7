/* SPDX-License-Identifier: Apache-2.0 */
/* Nelder-Mead: bounds by the change of variables, guards, progress. */
#include "br_test.h"

#include <string.h>

#include "nm/br_nm.h"

typedef struct {
    int outside;
    int calls;
} probe_t;

/* (x0 - 3)^2 + (x1 + 1)^2: unconstrained minimum (3, -1), outside the box below */
static double bowl(void *u, const double *x, int n)
{
    probe_t *p = u;
    (void)n;
    p->calls++;
    if (x[0] < 0.0 || x[0] > 2.0 || x[1] < 0.0 || x[1] > 1.0) p->outside++;
    return (x[0] - 3.0) * (x[0] - 3.0) + (x[1] + 1.0) * (x[1] + 1.0);
}

static void progress(void *u, int iter, int nfev, const double *xb, double fb, int n)
{
    (void)iter; (void)nfev; (void)xb; (void)fb; (void)n;
    ((probe_t *)u)->calls += 1000000;
}

static void test_bounds(void **st)
{
    (void)st;
    const double lo[2] = {0.0, 0.0}, hi[2] = {2.0, 1.0}, x0[2] = {1.0, 0.5};
    br_nm_cfg_t c;
    memset(&c, 0, sizeof c);
    c.n = 2;
    c.xatol = 1e-8;
    c.fatol = 1e-12;
    c.max_fev = 2000;
    c.lo = lo;
    c.hi = hi;
    probe_t p = {0, 0};
    br_nm_result_t r;
    assert_int_equal(br_nm_minimize(&c, bowl, &p, x0, &r), 0);
    /* the constrained minimum is the corner (2, 0); no evaluation left the box */
    BR_ASSERT_NEAR(r.x[0], 2.0, 1e-6);
    BR_ASSERT_NEAR(r.x[1], 0.0, 1e-6);
    assert_int_equal(p.outside, 0);
    assert_int_equal(r.nfev, p.calls);
}

static void test_guards_and_progress(void **st)
{
    (void)st;
    const double lo[2] = {0.0, 0.0}, hi[2] = {2.0, 1.0}, x0[2] = {1.0, 0.5}, bad[2] = {5.0, 0.5};
    br_nm_cfg_t c;
    memset(&c, 0, sizeof c);
    c.n = 2;
    c.xatol = 1e-4;
    c.fatol = 1e-4;
    c.max_fev = 100;
    br_nm_result_t r;
    probe_t p = {0, 0};
    c.n = 0;            assert_int_equal(br_nm_minimize(&c, bowl, &p, x0, &r), -1);
    c.n = BR_NM_MAX_DIM + 1; assert_int_equal(br_nm_minimize(&c, bowl, &p, x0, &r), -1);
    c.n = 2;
    c.max_fev = 2;      assert_int_equal(br_nm_minimize(&c, bowl, &p, x0, &r), -1);
    c.max_fev = 100;
    c.lo = lo;          assert_int_equal(br_nm_minimize(&c, bowl, &p, x0, &r), -1); /* lo without hi */
    c.hi = hi;          assert_int_equal(br_nm_minimize(&c, bowl, &p, bad, &r), -1); /* x0 outside */
    c.xatol = -1.0;     assert_int_equal(br_nm_minimize(&c, bowl, &p, x0, &r), -1);
    c.xatol = 1e-4;
    c.init_step = -0.1; assert_int_equal(br_nm_minimize(&c, bowl, &p, x0, &r), -1);
    c.init_step = 0.0;
    c.xatol = 1e-4;
    c.progress = progress;
    assert_int_equal(br_nm_minimize(&c, bowl, &p, x0, &r), 0);
    assert_true(p.calls / 1000000 == r.nit && r.nit > 0); /* one progress call per iteration */
    assert_true(r.nfev <= 100 + 2 + 1); /* budget; the last iteration may add reflection, contraction, shrink */
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_bounds), cmocka_unit_test(test_guards_and_progress)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
