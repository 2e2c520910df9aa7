/* A saved model (the "model.json" the diagnosis writes, docs/diagnose.md)
 * turned into a plant configuration, so the simulator can run an identified,
 * extended model.
 *
 * The file holds load-side parameters under "params":
 *   M_kg (the whole moving mass seen at the load, J/L^2 + M), Fv_Nspm,
 *   Fc_N, Fs_N, vs_mps, sigma0_Npm, sigma1_Nspm  (required)
 *   offset_N, Fc_neg_N, Fv_neg_Nspm, ripple_amp_N, ripple_period_m,
 *   ripple_phase_rad, grad_per_m, delay_s        (optional; absent = cause off)
 * Everything outside "params" is ignored; an unknown key inside it is an error.
 *
 * The lead, encoder, amplifier and substeps come from a base configuration;
 * M_kg is split between J and M in the base configuration's proportion. */
#ifndef BR_PLANT_JSON_H
#define BR_PLANT_JSON_H

#include <stddef.h>

#include "br_sim_plant.h"

/* 0 on success; -1 with "path:line: problem" in msg (unreadable file,
 * malformed JSON, a missing, unknown or non-numeric parameter). msg may be
 * NULL; msg_len bytes at most, NUL-terminated. The result is not validated
 * beyond that: br_plant_init does it. */
int br_plant_cfg_from_model_json(const char *path, const br_plant_cfg_t *base, br_plant_cfg_t *out, char *msg,
                                 size_t msg_len);

/* The same from a NUL-terminated text; name is used in messages. */
int br_plant_cfg_from_model_text(const char *text, const char *name, const br_plant_cfg_t *base, br_plant_cfg_t *out,
                                 char *msg, size_t msg_len);

#endif
