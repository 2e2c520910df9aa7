/* SPDX-License-Identifier: Apache-2.0 */
/* model.json -> plant configuration (sim/lib/plant/br_plant_json.c, by the table
 * sim/lib/plant/br_model_params.h): the mapping of the load-side parameters, and
 * one test per rejected input, each checking the line the message names. */
#define _POSIX_C_SOURCE 200809L /* mkstemp, fdopen, unlink */
#include "br_test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "plant/br_plant_json.h"

static const char *const good =
    "{\n"
    "  \"generator\": \"test\", \"causes\": [\"asymmetric_friction\", \"offset\"],\n"
    "  \"filter\": {\"order\": 4, \"fc_hz\": 20.0, \"nested\": [1, {\"a\": null}, true, false, \"s\\\"q\\u00e9\"]},\n"
    "  \"params\": {\n"
    "    \"Meff_kg\": 40.0, \"sigma2_Nspm\": 55.5, \"Fc_N\": 8.0, \"Fs_N\": 20.0, \"vs_mps\": 3e-5,\n"
    "    \"sigma0_Npm\": 5.0e6, \"sigma1_Nspm\": 1500,\n"
    "    \"offset_N\": -1.25, \"dFc_neg_N\": 1.0, \"dsigma2_neg_Nspm\": 15.0,\n"
    "    \"ripple_amp_N\": 0.5, \"ripple_period_m\": 0.008, \"ripple_phase_rad\": 1.0,\n"
    "    \"grad_per_m\": 2.0, \"delay_s\": 0.002\n"
    "  }\n"
    "}\n";

static int load(const char *text, br_plant_cfg_t *out, char *msg, size_t n)
{
    const br_plant_cfg_t base = br_plant_cfg_reference();
    return br_plant_cfg_from_model_text(text, "m.json", &base, out, msg, n);
}

static void test_mapping(void **st)
{
    (void)st;
    br_plant_cfg_t c, ref = br_plant_cfg_reference();
    char msg[256] = "";
    assert_int_equal(load(good, &c, msg, sizeof msg), 0);
    const double L = ref.lead_mprad;
    /* the moving mass at the load, split in the base machine's proportion */
    BR_ASSERT_NEAR((c.J_kgm2 + L * L * c.M_kg) / (L * L), 40.0, 1e-9);
    BR_ASSERT_NEAR(c.J_kgm2 / c.M_kg, ref.J_kgm2 / ref.M_kg, 1e-15);
    BR_ASSERT_NEAR(c.sigma2_Nspm, 55.5, 0.0);
    BR_ASSERT_NEAR(c.Fc_N, 8.0, 0.0);
    BR_ASSERT_NEAR(c.Fs_N, 20.0, 0.0);
    BR_ASSERT_NEAR(c.vs_mps, 3e-5, 0.0);
    BR_ASSERT_NEAR(c.sigma0_Npm, 5e6, 0.0);
    BR_ASSERT_NEAR(c.sigma1_Nspm, 1500.0, 0.0);
    BR_ASSERT_NEAR(c.offset_N, -1.25, 0.0);
    BR_ASSERT_NEAR(c.dFc_neg_N, 1.0, 0.0);
    BR_ASSERT_NEAR(c.dsigma2_neg_Nspm, 15.0, 0.0);
    BR_ASSERT_NEAR(c.ripple_amp_N, 0.5, 0.0);
    BR_ASSERT_NEAR(c.ripple_period_m, 0.008, 0.0);
    BR_ASSERT_NEAR(c.ripple_phase_rad, 1.0, 0.0);
    BR_ASSERT_NEAR(c.grad_per_m, 2.0, 0.0);
    BR_ASSERT_NEAR(c.delay_s, 0.002, 0.0);
    /* lead, encoder, amplifier, substeps from the base */
    assert_true(c.lead_mprad == ref.lead_mprad && c.counts_per_rev == ref.counts_per_rev &&
                c.tau_per_duty_Nm == ref.tau_per_duty_Nm && c.n_sub == ref.n_sub);
    br_plant_t p;
    const br_plant_state_t x0 = {0.0, 0.0, 0.0};
    assert_int_equal(br_plant_init(&p, &c, &x0), 0);
}

static void test_causes_default_off(void **st)
{
    (void)st;
    br_plant_cfg_t c;
    char msg[256];
    const char *t = "{\"params\": {\"Meff_kg\": 30, \"sigma2_Nspm\": 50, \"Fc_N\": 7, \"Fs_N\": 18, \"vs_mps\": 2e-5,"
                    " \"sigma0_Npm\": 4e6, \"sigma1_Nspm\": 2000}}";
    assert_int_equal(load(t, &c, msg, sizeof msg), 0);
    assert_int_equal(br_plant_causes_on(&c), 0);
}

/* each malformed input: -1 and the message names the line */
static void expect(const char *text, const char *want)
{
    br_plant_cfg_t c;
    char msg[256] = "";
    assert_int_equal(load(text, &c, msg, sizeof msg), -1);
    if (strstr(msg, want) == NULL) fail_msg("message \"%s\" lacks \"%s\"", msg, want);
}

static void test_rejects(void **st)
{
    (void)st;
    expect("[1, 2]", "m.json: a JSON object was expected");
    expect("{\"causes\": []}", "m.json: no \"params\" object");
    expect("{\n\"params\": {\"Meff_kg\": 30}\n}", "m.json: \"params\".\"sigma2_Nspm\": required, missing");
    expect("{\n\"params\": {\n\"Meff_kg\": 30,\n\"mass\": 3}}", "m.json: \"params\".\"mass\": unknown parameter");
    expect("{\"params\": {\n\"Meff_kg\": \"30\"}}", "m.json: \"params\".\"Meff_kg\": not a number");
    expect("{\"params\": {\"Meff_kg\": true}}", "\"params\".\"Meff_kg\": not a number");
    expect("{\"params\": {\"Meff_kg\": 1, \"Meff_kg\": 2}}", "\"params\".\"Meff_kg\": given twice");
    expect("{\"params\": {\"Meff_kg\": 1e999}}", "\"params\".\"Meff_kg\": number out of range");
    expect("{\"params\": {\"Meff_kg\": -1e999}}", "\"params\".\"Meff_kg\": number out of range");
    /* the names before they were unified (model format 1) are not read */
    expect("{\"params\": {\n\"M_kg\": 30}}", "\"params\".\"M_kg\": unknown parameter");
    expect("{\"params\": {\"Fv_Nspm\": 50}}", "\"params\".\"Fv_Nspm\": unknown parameter");
    expect("{\"params\": {\"Fc_neg_N\": 9}}", "\"params\".\"Fc_neg_N\": unknown parameter");
    expect("{\"params\": {\"Fv_neg_Nspm\": 70}}", "\"params\".\"Fv_neg_Nspm\": unknown parameter");
    /* each parameter's bounds (br_model_params.h) */
    expect("{\"params\": {\n\"Meff_kg\": 0}}", "m.json: \"params\".\"Meff_kg\": 0 must be > 0");
    expect("{\"params\": {\"Fc_N\": -7}}", "\"params\".\"Fc_N\": -7 must be > 0");
    expect("{\"params\": {\"sigma1_Nspm\": -1}}", "\"params\".\"sigma1_Nspm\": -1 must be in 0 .. 1e+08");
    expect("{\"params\": {\"ripple_period_m\": 0}}", "\"params\".\"ripple_period_m\": 0 must be > 0");
    expect("{\"params\": {\n\n\"delay_s\": 0.5}}", "\"params\".\"delay_s\": 0.5 must be in 0 .. 0.1");
    expect("{\"params\": {\"delay_s\": -0.001}}", "\"params\".\"delay_s\": -0.001 must be in 0 .. 0.1");
    expect("{\"params\": {}, \"params\": {}}", "m.json: \"params\" given twice");
    expect("{\"params\": 3}", "m.json: \"params\" must be an object");
    /* malformed JSON: cJSON's refusal, on the line where it stopped */
    expect("{\n\"a\": 1\n\"params\": {}}", "m.json:3: not valid JSON");
    expect("{\"a\": [1, 2}", "m.json:1: not valid JSON");
    expect("{\"a\":\n\"open}", "m.json:2: not valid JSON");
    expect("{\"a\": \"\\x\"}", "m.json:1: not valid JSON");
    expect("{\"params\": {}}\n\n x", "m.json:3: not valid JSON");
    expect("{\"a\" 1}", "m.json:1: not valid JSON");
    expect("{\"a\": tru}", "m.json:1: not valid JSON");
    expect("", "m.json:1: not valid JSON");
    /* nesting beyond cJSON's limit (CJSON_NESTING_LIMIT, 1000) */
    static char deep[1200], doc[1300];
    memset(deep, '[', sizeof deep - 1);
    deep[sizeof deep - 1] = '\0';
    snprintf(doc, sizeof doc, "{\"a\": %s}", deep);
    expect(doc, "m.json:1: not valid JSON (or nested too deeply)");
}

static void test_file(void **st)
{
    (void)st;
    char path[] = "/tmp/br_test_model_XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "wb");
    fputs("\xEF\xBB\xBF", f); /* a byte-order mark is tolerated */
    fputs(good, f);
    fclose(f);
    const br_plant_cfg_t base = br_plant_cfg_reference();
    br_plant_cfg_t c;
    char msg[256] = "";
    assert_int_equal(br_plant_cfg_from_model_json(path, &base, &c, msg, sizeof msg), 0);
    BR_ASSERT_NEAR(c.Fc_N, 8.0, 0.0);
    unlink(path);
    assert_int_equal(br_plant_cfg_from_model_json(path, &base, &c, msg, sizeof msg), -1);
    assert_non_null(strstr(msg, ":0: cannot open"));
}

/* the 1 MiB limit (MAX_FILE_BYTES): a valid model padded with spaces to
 * exactly 1 MiB is read, one byte more is refused; a FIFO is refused before
 * it is opened (an open would wait for a writer) */
static void write_padded(const char *path, long size)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(good, f);
    for (long k = (long)strlen(good); k < size; k++) fputc(' ', f);
    assert_int_equal(fclose(f), 0);
}

static void test_size_limit(void **st)
{
    (void)st;
    char path[] = "/tmp/br_test_model_big_XXXXXX";
    const int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    const br_plant_cfg_t base = br_plant_cfg_reference();
    br_plant_cfg_t c;
    char msg[256] = "";
    write_padded(path, 1L << 20);
    assert_int_equal(br_plant_cfg_from_model_json(path, &base, &c, msg, sizeof msg), 0);
    write_padded(path, (1L << 20) + 1);
    assert_int_equal(br_plant_cfg_from_model_json(path, &base, &c, msg, sizeof msg), -1);
    assert_non_null(strstr(msg, ":0: larger than 1 MiB"));
    unlink(path);
    assert_int_equal(mkfifo(path, 0600), 0);
    assert_int_equal(br_plant_cfg_from_model_json(path, &base, &c, msg, sizeof msg), -1);
    assert_non_null(strstr(msg, ":0: not a regular file"));
    unlink(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mapping),
        cmocka_unit_test(test_causes_default_off),
        cmocka_unit_test(test_rejects),
        cmocka_unit_test(test_file),
        cmocka_unit_test(test_size_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
