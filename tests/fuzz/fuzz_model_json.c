/* SPDX-License-Identifier: Apache-2.0 */
/* libFuzzer target: the model reader (sim/lib/plant/br_plant_json.c: cJSON, then
 * the checks of the parameter table), which reads a diagnosis's model.json,
 * outside data. (Debian's libcjson is not instrumented for coverage: the
 * fuzzer is guided by the checks' branches, and ASan still watches cJSON's
 * allocations.) The input is XORed over a valid
 * model (every parameter of the table in br_model_params.h, the reference
 * machine's values and 0.5 for each cause), the rest appended, so the fuzzer
 * works inside the structure, not only on its first brace. Every input must
 * be refused with a message or give a configuration the plant either accepts
 * or refuses at init; never a crash or a sanitizer report.
 * docs/reliability.md. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <stdio.h>

#include "plant/br_model_params.h"
#include "plant/br_plant_json.h"
#include "plant/br_sim_plant.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static char text[8192];
    const br_plant_cfg_t base = br_plant_cfg_reference();
    /* the valid model, from the one table of parameter names */
    size_t n = (size_t)snprintf(text, sizeof text, "{\"format\": \"bristle-model/2\", \"params\": {");
#define BR_FUZZ_MEFF(json, tok, unit, lo, hi) \
    n += (size_t)snprintf(text + n, sizeof text - n, "\"%s\": %.17g, ", json, base.M_kg);
#define BR_FUZZ_NOM(json, field, unit, lo, hi) \
    n += (size_t)snprintf(text + n, sizeof text - n, "\"%s\": %.17g, ", json, base.field);
#define BR_FUZZ_CAUSE(json, field, unit, lo, hi, cause, option, req) \
    n += (size_t)snprintf(text + n, sizeof text - n, "\"%s\": 0.5, ", json);
    BR_MEFF_PARAM(BR_FUZZ_MEFF)
    BR_NOMINAL_PARAMS(BR_FUZZ_NOM)
    BR_CAUSE_PARAMS(BR_FUZZ_CAUSE)
    n -= 2; /* the last ", " */
    n += (size_t)snprintf(text + n, sizeof text - n, "}}");
    if (n + size >= sizeof text) return 0;
    for (size_t i = 0; i < size && i < n; i++) text[i] ^= (char)data[i];
    if (size > n) memcpy(text + n, data + n, size - n);
    text[n > size ? n : size] = '\0';
    br_plant_cfg_t out;
    char msg[256];
    msg[0] = '\0';
    const int rc = br_plant_cfg_from_model_text(text, "fuzz.json", &base, &out, msg, sizeof msg);
    if (rc != 0) {
        if (msg[0] == '\0' || strlen(msg) >= sizeof msg) abort(); /* a refusal says why, within its buffer */
        return 0;
    }
    /* accepted: the plant validates it, and a valid one steps to finite values */
    br_plant_t p;
    const br_plant_state_t x0 = {0.0, 0.0, 0.0};
    if (br_plant_init(&p, &out, &x0) == 0) {
        for (int k = 0; k < 10; k++) br_plant_step(&p, 0.1, 1e-3);
    }
    return 0;
}
