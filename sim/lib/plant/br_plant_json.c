/* SPDX-License-Identifier: Apache-2.0 */
/* model.json -> br_plant_cfg_t (br_plant_json.h). The JSON is read by cJSON
 * (Debian's libcjson-dev, docs/architecture.md); this file keeps only the
 * numbers under the top-level "params", by the table of br_model_params.h. */
#define _POSIX_C_SOURCE 200809L /* stat */
#include "br_plant_json.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "br_model_params.h"

#define MAX_FILE_BYTES (1L << 20)

/* the parameters a model may hold (br_model_params.h): the moving mass and
 * the nominal ones are required, the causes' optional */
#define ENUM_ROW(json, token, ...) P_##token,
enum { BR_MEFF_PARAM(ENUM_ROW) BR_NOMINAL_PARAMS(ENUM_ROW) N_REQUIRED };
enum { P_CAUSES = N_REQUIRED - 1, BR_CAUSE_PARAMS(ENUM_ROW) P_COUNT };
#undef ENUM_ROW

typedef struct {
    const char *name;
    double lo, hi;
} param_t;
#define ROW(json, token, unit, lo, hi) {json, lo, hi},
#define CAUSE_ROW(json, field, unit, lo, hi, cause, option, required) {json, lo, hi},
static const param_t params[P_COUNT] = {BR_MEFF_PARAM(ROW) BR_NOMINAL_PARAMS(ROW) BR_CAUSE_PARAMS(CAUSE_ROW)};
#undef ROW
#undef CAUSE_ROW

/* "name:line: what" (line 0: the file as a whole), or "name: where: what" for
 * a field, named by its path ("params"."Fc_N"): cJSON keeps no line numbers */
static int fail_at(char *msg, size_t msg_len, const char *name, int line, const char *what)
{
    if (msg && msg_len) snprintf(msg, msg_len, "%s:%d: %s", name, line, what);
    return -1;
}

static int fail_field(char *msg, size_t msg_len, const char *name, const char *key, const char *what)
{
    if (msg && msg_len) {
        if (key)
            snprintf(msg, msg_len, "%s: \"params\".\"%s\": %s", name, key, what);
        else
            snprintf(msg, msg_len, "%s: %s", name, what);
    }
    return -1;
}

/* the line of a position in text (1-based) */
static int line_of(const char *text, const char *at)
{
    int line = 1;
    for (const char *p = text; p < at && *p; p++) line += *p == '\n';
    return line;
}

/* the "params" object into val/have: numbers only, known keys only, each once */
static int read_params(const cJSON *po, const char *name, double val[P_COUNT], int have[P_COUNT], char *msg,
                       size_t msg_len)
{
    char what[160], bounds[64];
    if (!cJSON_IsObject(po)) return fail_field(msg, msg_len, name, NULL, "\"params\" must be an object");
    for (const cJSON *it = po->child; it; it = it->next) {
        const char *key = it->string;
        int k = 0;
        while (k < P_COUNT && strcmp(key, params[k].name) != 0) k++;
        if (k == P_COUNT) return fail_field(msg, msg_len, name, key, "unknown parameter");
        if (have[k]) return fail_field(msg, msg_len, name, key, "given twice");
        if (!cJSON_IsNumber(it)) return fail_field(msg, msg_len, name, key, "not a number");
        const double v = it->valuedouble;
        if (!isfinite(v)) return fail_field(msg, msg_len, name, key, "number out of range");
        if (!br_param_in_bounds(v, params[k].lo, params[k].hi)) {
            br_param_bounds_text(params[k].lo, params[k].hi, bounds, sizeof bounds);
            snprintf(what, sizeof what, "%g %s", v, bounds);
            return fail_field(msg, msg_len, name, key, what);
        }
        val[k] = v;
        have[k] = 1;
    }
    return 0;
}

int br_plant_cfg_from_model_text(const char *text, const char *name, const br_plant_cfg_t *base, br_plant_cfg_t *out,
                                 char *msg, size_t msg_len)
{
    const char *end = NULL;
    /* the whole text one JSON value, nothing after it */
    cJSON *root = cJSON_ParseWithOpts(text, &end, 1);
    if (!root) {
        const char *at = end ? end : text;
        return fail_at(msg, msg_len, name, line_of(text, at), "not valid JSON (or nested too deeply) here");
    }
    double val[P_COUNT] = {0};
    int have[P_COUNT] = {0}, rc = 0;
    const cJSON *po = NULL;
    if (!cJSON_IsObject(root)) {
        rc = fail_field(msg, msg_len, name, NULL, "a JSON object was expected");
    } else {
        for (const cJSON *it = root->child; it && rc == 0; it = it->next) {
            if (strcmp(it->string, "params") != 0) continue; /* everything outside "params" is ignored */
            if (po) rc = fail_field(msg, msg_len, name, NULL, "\"params\" given twice");
            po = it;
        }
        if (rc == 0 && !po) rc = fail_field(msg, msg_len, name, NULL, "no \"params\" object");
        if (rc == 0) rc = read_params(po, name, val, have, msg, msg_len);
        for (int k = 0; rc == 0 && k < N_REQUIRED; k++)
            if (!have[k]) rc = fail_field(msg, msg_len, name, params[k].name, "required, missing");
    }
    cJSON_Delete(root);
    if (rc != 0) return rc;
    *out = *base;
    /* the moving mass at the load, split between J and M like the base machine */
    const double L = base->lead_mprad;
    const double scale = val[P_Meff_kg] * L * L / (base->J_kgm2 + L * L * base->M_kg);
    out->J_kgm2 = base->J_kgm2 * scale;
    out->M_kg = base->M_kg * scale;
    /* the other parameters set the fields of their names (absent causes: 0, off) */
#define SET_ROW(json, field, ...) out->field = val[P_##field];
    BR_NOMINAL_PARAMS(SET_ROW)
    BR_CAUSE_PARAMS(SET_ROW)
#undef SET_ROW
    return 0;
}

int br_plant_cfg_from_model_json(const char *path, const br_plant_cfg_t *base, br_plant_cfg_t *out, char *msg,
                                 size_t msg_len)
{
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode)) /* a FIFO's open would wait, a device never end */
        return fail_at(msg, msg_len, path, 0, "not a regular file (a device, a FIFO or a folder)");
    FILE *f = fopen(path, "rb");
    if (!f) {
        char what[256];
        snprintf(what, sizeof what, "cannot open: %s", strerror(errno));
        return fail_at(msg, msg_len, path, 0, what);
    }
    char *buf = malloc((size_t)MAX_FILE_BYTES + 1);
    if (!buf) {
        fclose(f);
        return fail_at(msg, msg_len, path, 0, "out of memory");
    }
    const size_t n = fread(buf, 1, (size_t)MAX_FILE_BYTES + 1, f);
    const int err = ferror(f);
    fclose(f);
    int rc = -1;
    if (err) {
        fail_at(msg, msg_len, path, 0, "read error");
    } else if (n > (size_t)MAX_FILE_BYTES) {
        fail_at(msg, msg_len, path, 0, "larger than 1 MiB, not a model file");
    } else if (memchr(buf, '\0', n)) {
        fail_at(msg, msg_len, path, 0, "binary content (NUL byte)");
    } else {
        buf[n] = '\0';
        /* a UTF-8 byte-order mark is tolerated */
        const char *text = (n >= 3 && memcmp(buf, "\xEF\xBB\xBF", 3) == 0) ? buf + 3 : buf;
        rc = br_plant_cfg_from_model_text(text, path, base, out, msg, msg_len);
    }
    free(buf);
    return rc;
}
