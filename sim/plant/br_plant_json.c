/* model.json -> br_plant_cfg_t (br_plant_json.h): a small recursive-descent
 * JSON reader that keeps only the numbers under the top-level "params", by
 * the table of br_model_params.h. */
#include "br_plant_json.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "br_model_params.h"

#define MAX_DEPTH 32
#define MAX_FILE_BYTES (1L << 20)
#define KEY_LEN 64

typedef struct {
    const char *s;
    size_t i;
    int line;
    const char *name;
    char *msg;
    size_t msg_len;
} json_t;

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

static int fail(const json_t *j, const char *what)
{
    if (j->msg && j->msg_len) snprintf(j->msg, j->msg_len, "%s:%d: %s", j->name, j->line, what);
    return -1;
}

static int fail_file(char *msg, size_t msg_len, const char *path, const char *what, const char *detail)
{
    if (msg && msg_len) snprintf(msg, msg_len, "%s:0: %s%s", path, what, detail ? detail : "");
    return -1;
}

static void skip_ws(json_t *j)
{
    for (;;) {
        const char c = j->s[j->i];
        if (c == '\n') j->line++;
        if (c == ' ' || c == '\t' || c == '\r' || c == '\n') j->i++;
        else return;
    }
}

/* a string into buf (escapes reduced to one character; too long is an error) */
static int parse_string(json_t *j, char *buf, size_t cap)
{
    if (j->s[j->i] != '"') return fail(j, "a string was expected");
    j->i++;
    size_t n = 0;
    for (;;) {
        char c = j->s[j->i];
        if (c == '\0' || c == '\n') return fail(j, "unterminated string");
        j->i++;
        if (c == '"') break;
        if (c == '\\') {
            c = j->s[j->i];
            if (c == '\0') return fail(j, "unterminated string");
            j->i++;
            if (c == 'u') {
                for (int k = 0; k < 4; k++, j->i++) {
                    if (!strchr("0123456789abcdefABCDEF", j->s[j->i]) || j->s[j->i] == '\0') return fail(j, "bad \\u escape");
                }
                c = '?';
            } else if (!strchr("\"\\/bfnrt", c)) {
                return fail(j, "bad escape in a string");
            }
        }
        if (buf) {
            if (n + 1 >= cap) return fail(j, "string too long");
            buf[n++] = c;
        }
    }
    if (buf) buf[n] = '\0';
    return 0;
}

/* a JSON number (RFC 8259 grammar) */
static int parse_number(json_t *j, double *out)
{
    const char *p = j->s + j->i, *q = p;
    if (*q == '-') q++;
    if (*q == '0') q++;
    else if (*q >= '1' && *q <= '9') while (*q >= '0' && *q <= '9') q++;
    else return fail(j, "a number was expected");
    if (*q == '.') {
        q++;
        if (!(*q >= '0' && *q <= '9')) return fail(j, "malformed number");
        while (*q >= '0' && *q <= '9') q++;
    }
    if (*q == 'e' || *q == 'E') {
        q++;
        if (*q == '+' || *q == '-') q++;
        if (!(*q >= '0' && *q <= '9')) return fail(j, "malformed number");
        while (*q >= '0' && *q <= '9') q++;
    }
    errno = 0;
    char *end = NULL;
    const double v = strtod(p, &end);
    if (end != q) return fail(j, "malformed number");
    if (errno == ERANGE || !isfinite(v)) return fail(j, "number out of range");
    *out = v;
    j->i += (size_t)(q - p);
    return 0;
}

static int skip_value(json_t *j, int depth);

static int skip_container(json_t *j, int depth, char close, int keyed)
{
    if (depth > MAX_DEPTH) return fail(j, "nested too deeply");
    j->i++;
    skip_ws(j);
    if (j->s[j->i] == close) {
        j->i++;
        return 0;
    }
    for (;;) {
        skip_ws(j);
        if (keyed) {
            if (parse_string(j, NULL, 0) != 0) return -1;
            skip_ws(j);
            if (j->s[j->i] != ':') return fail(j, "':' expected after a key");
            j->i++;
            skip_ws(j);
        }
        if (skip_value(j, depth + 1) != 0) return -1;
        skip_ws(j);
        if (j->s[j->i] == ',') {
            j->i++;
            continue;
        }
        if (j->s[j->i] == close) {
            j->i++;
            return 0;
        }
        return fail(j, keyed ? "',' or '}' expected" : "',' or ']' expected");
    }
}

static int skip_value(json_t *j, int depth)
{
    const char c = j->s[j->i];
    double d;
    if (c == '{') return skip_container(j, depth, '}', 1);
    if (c == '[') return skip_container(j, depth, ']', 0);
    if (c == '"') return parse_string(j, NULL, 0);
    static const char *const lit[3] = {"true", "false", "null"};
    for (int k = 0; k < 3; k++) {
        const size_t n = strlen(lit[k]);
        if (strncmp(j->s + j->i, lit[k], n) == 0) {
            j->i += n;
            return 0;
        }
    }
    return parse_number(j, &d);
}

/* the "params" object: numbers only, known keys only, each once */
static int parse_params(json_t *j, double val[P_COUNT], int have[P_COUNT])
{
    char key[KEY_LEN], msg[200], bounds[64];
    if (j->s[j->i] != '{') return fail(j, "\"params\" must be an object");
    j->i++;
    skip_ws(j);
    if (j->s[j->i] == '}') {
        j->i++;
        return 0;
    }
    for (;;) {
        skip_ws(j);
        if (parse_string(j, key, sizeof key) != 0) return -1;
        int k = 0;
        while (k < P_COUNT && strcmp(key, params[k].name) != 0) k++;
        if (k == P_COUNT) {
            snprintf(msg, sizeof msg, "unknown parameter \"%s\" in \"params\"", key);
            return fail(j, msg);
        }
        if (have[k]) {
            snprintf(msg, sizeof msg, "parameter \"%s\" given twice", key);
            return fail(j, msg);
        }
        skip_ws(j);
        if (j->s[j->i] != ':') return fail(j, "':' expected after a key");
        j->i++;
        skip_ws(j);
        const char c = j->s[j->i];
        if (!(c == '-' || (c >= '0' && c <= '9'))) {
            snprintf(msg, sizeof msg, "parameter \"%s\" is not a number", key);
            return fail(j, msg);
        }
        if (parse_number(j, &val[k]) != 0) return -1;
        if (!br_param_in_bounds(val[k], params[k].lo, params[k].hi)) {
            br_param_bounds_text(params[k].lo, params[k].hi, bounds, sizeof bounds);
            snprintf(msg, sizeof msg, "parameter \"%s\" = %g %s", key, val[k], bounds);
            return fail(j, msg);
        }
        have[k] = 1;
        skip_ws(j);
        if (j->s[j->i] == ',') {
            j->i++;
            continue;
        }
        if (j->s[j->i] == '}') {
            j->i++;
            return 0;
        }
        return fail(j, "',' or '}' expected");
    }
}

int br_plant_cfg_from_model_text(const char *text, const char *name, const br_plant_cfg_t *base, br_plant_cfg_t *out,
                                 char *msg, size_t msg_len)
{
    json_t j = {text, 0, 1, name, msg, msg_len};
    double val[P_COUNT] = {0};
    int have[P_COUNT] = {0}, seen_params = 0, params_line = 0;
    char key[KEY_LEN], what[160];
    skip_ws(&j);
    if (j.s[j.i] != '{') return fail(&j, "a JSON object was expected");
    j.i++;
    skip_ws(&j);
    if (j.s[j.i] != '}') {
        for (;;) {
            skip_ws(&j);
            if (parse_string(&j, key, sizeof key) != 0) return -1;
            skip_ws(&j);
            if (j.s[j.i] != ':') return fail(&j, "':' expected after a key");
            j.i++;
            skip_ws(&j);
            if (strcmp(key, "params") == 0) {
                if (seen_params) return fail(&j, "\"params\" given twice");
                seen_params = 1;
                params_line = j.line;
                if (parse_params(&j, val, have) != 0) return -1;
            } else if (skip_value(&j, 1) != 0) {
                return -1;
            }
            skip_ws(&j);
            if (j.s[j.i] == ',') {
                j.i++;
                continue;
            }
            if (j.s[j.i] == '}') break;
            return fail(&j, "',' or '}' expected");
        }
    }
    j.i++;
    skip_ws(&j);
    if (j.s[j.i] != '\0') return fail(&j, "text after the JSON object");
    if (!seen_params) return fail(&j, "no \"params\" object");
    for (int k = 0; k < N_REQUIRED; k++) {
        if (!have[k]) {
            snprintf(what, sizeof what, "\"params\" lacks \"%s\"", params[k].name);
            j.line = params_line; /* the line where "params" opens */
            return fail(&j, what);
        }
    }
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
    FILE *f = fopen(path, "rb");
    if (!f) return fail_file(msg, msg_len, path, "cannot open: ", strerror(errno));
    char *buf = malloc((size_t)MAX_FILE_BYTES + 1);
    if (!buf) {
        fclose(f);
        return fail_file(msg, msg_len, path, "out of memory", NULL);
    }
    const size_t n = fread(buf, 1, (size_t)MAX_FILE_BYTES + 1, f);
    const int err = ferror(f);
    fclose(f);
    int rc = -1;
    if (err) {
        fail_file(msg, msg_len, path, "read error", NULL);
    } else if (n > (size_t)MAX_FILE_BYTES) {
        fail_file(msg, msg_len, path, "larger than 1 MiB, not a model file", NULL);
    } else if (memchr(buf, '\0', n)) {
        fail_file(msg, msg_len, path, "binary content (NUL byte)", NULL);
    } else {
        buf[n] = '\0';
        /* a UTF-8 byte-order mark is tolerated */
        const char *text = (n >= 3 && memcmp(buf, "\xEF\xBB\xBF", 3) == 0) ? buf + 3 : buf;
        rc = br_plant_cfg_from_model_text(text, path, base, out, msg, msg_len);
    }
    free(buf);
    return rc;
}
