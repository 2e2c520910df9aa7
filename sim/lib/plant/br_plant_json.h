/* SPDX-License-Identifier: Apache-2.0 */
/* A saved model (the "model.json" the diagnosis writes, docs/diagnose.md)
 * turned into a plant configuration, so the simulator can run an identified,
 * extended model.
 *
 * The file holds load-side parameters under "params", named by the table of
 * br_model_params.h: Meff_kg (the moving mass at the load, J/L^2 + M) and the
 * nominal ones are required, the causes' optional (absent = cause off); each
 * sets the br_plant_cfg_t field of its name. Everything outside "params" is
 * ignored; an unknown key inside it is an error, and so is a value outside
 * its bounds. (Models written before the names were unified, format
 * "bristle-model/1", are refused: they hold M_kg, Fv_Nspm, Fc_neg_N.)
 *
 * The lead, encoder, amplifier and substeps come from a base configuration;
 * Meff_kg is split between J and M in the base configuration's proportion. */
#ifndef BR_PLANT_JSON_H
#define BR_PLANT_JSON_H

#include <stddef.h>

#include "br_sim_plant.h"

/* 0 on success; -1 with the problem in msg: "path:line: ..." for an
 * unreadable file (line 0) or malformed JSON (the line where cJSON stopped),
 * "path: "params"."key": ..." for a missing, unknown, repeated, non-numeric
 * or out-of-bounds parameter. msg may be NULL; msg_len bytes at most,
 * NUL-terminated. The result is not validated beyond that: br_plant_init does it. */
int br_plant_cfg_from_model_json(const char *path, const br_plant_cfg_t *base, br_plant_cfg_t *out, char *msg,
                                 size_t msg_len);

/* The same from a NUL-terminated text; name is used in messages. */
int br_plant_cfg_from_model_text(const char *text, const char *name, const br_plant_cfg_t *base, br_plant_cfg_t *out,
                                 char *msg, size_t msg_len);

#endif
