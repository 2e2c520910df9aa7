/* SPDX-License-Identifier: Apache-2.0 */
/* Writing a tool's output so that a failed run leaves nothing behind: the
 * text goes to a temporary file in the destination's directory and is
 * renamed onto the destination only when the whole run succeeded. Until
 * then an existing file of that name is untouched, byte for byte; a
 * failed or abandoned run removes its temporary file. docs/tools.md. */
#ifndef BR_OUTFILE_H
#define BR_OUTFILE_H

#include <stdio.h>

#define BR_OUTFILE_PATH_MAX 4096

typedef struct {
    FILE *f; /* write here; NULL when not open */
    char path[BR_OUTFILE_PATH_MAX];
    char tmp[BR_OUTFILE_PATH_MAX];
} br_outfile_t;

/* Creates "<dir>/.<name>.tmp-XXXXXX" beside path and opens it in o->f.
 * 0, or -1 with "tool: cannot write path: reason" on stderr (no such
 * directory, not writable, path names a directory or another non-regular
 * file, path too long); path is never touched. */
int br_outfile_open(br_outfile_t *o, const char *tool, const char *path);

/* Checks that every write succeeded, flushes to disk, closes and renames
 * the temporary file onto path: 0, or -1 with a message (the temporary
 * removed, path untouched). */
int br_outfile_commit(br_outfile_t *o, const char *tool);

/* Closes and removes the temporary file, if any; path untouched. Safe on a
 * zeroed, committed or already discarded o. */
void br_outfile_discard(br_outfile_t *o);

#endif
