/* SPDX-License-Identifier: Apache-2.0 */
/* The cause options' rows generated from the cause registry
 * (bristle_gen/model/br_causes.h): br_causes_apply lays a cause over a plant
 * when a field that switches it on differs from the reference machine's, all
 * of its fields and none of another cause's; br_cause_usage prints one line
 * per option with its rows' names, the optional ones in brackets, and its
 * cause. Every expectation is read from the tables, so a new cause is held by
 * the same tests. */
#include "br_test.h"

#include <stddef.h>
#include <string.h>

#include "cause_args/br_cause_args.h"

/* br_plant_cfg_t's cause fields: the registry's rows */
static const struct {
    const char *cause;
    size_t off;
    int on;
} FIELDS[] = {
#define FIELD_ROW(field, cause, hook, on) {#cause, offsetof(br_plant_cfg_t, field), on},
    BR_CAUSE_FIELDS(FIELD_ROW)
#undef FIELD_ROW
};
#define N_FIELDS ((int)(sizeof FIELDS / sizeof FIELDS[0]))

static double *at(br_plant_cfg_t *c, int i)
{
    return (double *)((char *)c + FIELDS[i].off);
}

/* a plant whose every cause field is marked (so a copied 0 shows) */
static br_plant_cfg_t marked_plant(void)
{
    br_plant_cfg_t p = br_plant_cfg_reference();
    for (int i = 0; i < N_FIELDS; i++) *at(&p, i) = 7.0;
    return p;
}

static void test_a_switch_lays_its_whole_cause(void **st)
{
    (void)st;
    int switches = 0;
    for (int i = 0; i < N_FIELDS; i++) {
        if (!FIELDS[i].on) continue;
        switches++;
        br_plant_cfg_t opt = br_plant_cfg_reference(), plant = marked_plant();
        *at(&opt, i) = 0.5;
        br_causes_apply(&plant, &opt);
        for (int k = 0; k < N_FIELDS; k++) {
            const int same = strcmp(FIELDS[k].cause, FIELDS[i].cause) == 0;
            /* the cause's fields are the options' (0.5, the others 0); another cause's stay */
            assert_true(*at(&plant, k) == (same ? *at(&opt, k) : 7.0));
        }
    }
    assert_true(switches > 0);
}

static void test_a_field_that_does_not_switch_lays_nothing(void **st)
{
    (void)st;
    for (int i = 0; i < N_FIELDS; i++) {
        if (FIELDS[i].on) continue;
        br_plant_cfg_t opt = br_plant_cfg_reference(), plant = marked_plant();
        *at(&opt, i) = 0.5; /* a ripple's period alone is no ripple */
        br_causes_apply(&plant, &opt);
        for (int k = 0; k < N_FIELDS; k++) assert_true(*at(&plant, k) == 7.0);
    }
    /* nothing set: the plant as it was */
    br_plant_cfg_t opt = br_plant_cfg_reference(), plant = marked_plant();
    br_causes_apply(&plant, &opt);
    for (int k = 0; k < N_FIELDS; k++) assert_true(*at(&plant, k) == 7.0);
}

/* the usage text on a temporary file, read back */
static void usage_text(const char *note, char *buf, size_t n)
{
    FILE *f = tmpfile();
    assert_non_null(f);
    br_cause_usage(f, note);
    rewind(f);
    const size_t got = fread(buf, 1, n - 1, f);
    assert_true(got < n - 1);
    buf[got] = '\0';
    fclose(f);
}

/* one row of BR_CAUSE_PARAMS in the text: the option's line "    --option first,...",
 * ending with its cause, holds its name, after "[," when optional */
static void check_row(const char *text, const char *name, const char *cause, const char *option, int req)
{
    char want[128];
    snprintf(want, sizeof want, "\n    %s ", option);
    const char *line = strstr(text, want);
    assert_non_null(line);
    const char *end = strchr(line + 1, '\n');
    assert_non_null(end);
    snprintf(want, sizeof want, "%s%s", req ? "" : "[,", name);
    const char *at_name = strstr(line, want);
    assert_true(at_name != NULL && at_name < end);
    assert_true(req || strstr(line, "]") < end);
    const size_t lc = strlen(cause);
    assert_true((size_t)(end - line) > lc && memcmp(end - lc, cause, lc) == 0);
    assert_true(end[-(long)lc - 1] == ' ');
}

static void test_usage_lists_every_row(void **st)
{
    (void)st;
    char text[4096];
    usage_text("", text, sizeof text);
#define CHECK_ROW(json, fld, unit, lo, hi, cause, option, req) check_row(text, json, cause, option, req);
    BR_CAUSE_PARAMS(CHECK_ROW)
#undef CHECK_ROW
    /* no note: the heading's two lines, then the options */
    assert_non_null(strstr(text, "\"Parameters\")\n    --"));
    usage_text("(a note)", text, sizeof text);
    assert_non_null(strstr(text, "\"Parameters\")\n                      (a note)\n    --"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_a_switch_lays_its_whole_cause),
        cmocka_unit_test(test_a_field_that_does_not_switch_lays_nothing),
        cmocka_unit_test(test_usage_lists_every_row),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
