/* SPDX-License-Identifier: Apache-2.0 */
/* Temporary file + rename (br_outfile.h). */
#define _POSIX_C_SOURCE 200809L
#include "br_outfile.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int refuse(const char *tool, const char *path, const char *why)
{
    fprintf(stderr, "%s: cannot write %s: %s\n", tool, path, why);
    return -1;
}

int br_outfile_open(br_outfile_t *o, const char *tool, const char *path)
{
    memset(o, 0, sizeof *o);
    const size_t n = strlen(path);
    if (n == 0) return refuse(tool, path, "empty path");
    if (n + 16 >= sizeof o->tmp) return refuse(tool, path, "path too long");
    struct stat st;
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode))
        return refuse(tool, path, S_ISDIR(st.st_mode) ? "is a directory" : "not a regular file");
    memcpy(o->path, path, n + 1);
    const char *slash = strrchr(path, '/');
    const size_t dir_len = slash ? (size_t)(slash - path) + 1 : 0; /* with its '/' */
    snprintf(o->tmp, sizeof o->tmp, "%.*s.%s.tmp-XXXXXX", (int)dir_len, path, path + dir_len);
    const int fd = mkstemp(o->tmp);
    if (fd < 0) {
        const int e = errno;
        o->tmp[0] = '\0';
        return refuse(tool, path, strerror(e));
    }
    const mode_t mask = umask(0);
    umask(mask);
    if (fchmod(fd, 0666 & ~mask) != 0 || !(o->f = fdopen(fd, "w"))) {
        const int e = errno;
        close(fd);
        unlink(o->tmp);
        o->tmp[0] = '\0';
        return refuse(tool, path, strerror(e));
    }
    return 0;
}

int br_outfile_commit(br_outfile_t *o, const char *tool)
{
    if (!o->f) return refuse(tool, o->path, "not open");
    int ok = fflush(o->f) == 0 && !ferror(o->f) && fsync(fileno(o->f)) == 0;
    int e = errno;
    if (fclose(o->f) != 0 && ok) {
        ok = 0;
        e = errno;
    }
    o->f = NULL;
    if (ok && rename(o->tmp, o->path) != 0) {
        ok = 0;
        e = errno;
    }
    if (!ok) {
        unlink(o->tmp);
        o->tmp[0] = '\0';
        return refuse(tool, o->path, strerror(e));
    }
    o->tmp[0] = '\0';
    return 0;
}

void br_outfile_discard(br_outfile_t *o)
{
    if (o->f) fclose(o->f);
    o->f = NULL;
    if (o->tmp[0]) unlink(o->tmp);
    o->tmp[0] = '\0';
}
