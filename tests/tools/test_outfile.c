/* SPDX-License-Identifier: Apache-2.0 */
/* br_outfile (sim/lib/tool/br_outfile.h): an existing destination survives a
 * discarded write byte for byte, a committed write replaces it whole, no
 * temporary file is left behind, and a destination that cannot be written
 * is refused at open. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "tool/br_outfile.h"
#include "br_test.h"

static char dir[256];

static void put(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
}

static void expect(const char *path, const char *text)
{
    char buf[256] = {0};
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    const size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    assert_int_equal(n, strlen(text));
    assert_string_equal(buf, text);
}

/* files in dir besides "keep" */
static int others(void)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..") && strcmp(e->d_name, "keep")) n++;
    closedir(d);
    return n;
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/br_outfile_XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static void test_discard_keeps_existing(void **state)
{
    (void)state;
    char path[300];
    snprintf(path, sizeof path, "%s/keep", dir);
    put(path, "old contents\n");
    br_outfile_t o;
    assert_int_equal(br_outfile_open(&o, "test", path), 0);
    fputs("half a new file", o.f);
    expect(path, "old contents\n"); /* untouched while the run goes on */
    assert_int_equal(others(), 1);   /* the temporary file, beside it */
    br_outfile_discard(&o);
    expect(path, "old contents\n");
    assert_int_equal(others(), 0);
    br_outfile_discard(&o); /* twice is harmless */
}

static void test_commit_replaces(void **state)
{
    (void)state;
    char path[300];
    snprintf(path, sizeof path, "%s/keep", dir);
    put(path, "old contents\n");
    br_outfile_t o;
    assert_int_equal(br_outfile_open(&o, "test", path), 0);
    fputs("new contents\n", o.f);
    assert_int_equal(br_outfile_commit(&o, "test"), 0);
    expect(path, "new contents\n");
    assert_int_equal(others(), 0);
    struct stat st;
    assert_int_equal(stat(path, &st), 0);
    const mode_t mask = umask(0);
    umask(mask);
    assert_int_equal(st.st_mode & 0777, 0666 & ~mask); /* not mkstemp's 0600 */
    br_outfile_discard(&o);                             /* after a commit: nothing to remove */
    expect(path, "new contents\n");
}

static void test_relative_path(void **state)
{
    (void)state;
    char cwd[512];
    assert_non_null(getcwd(cwd, sizeof cwd));
    assert_int_equal(chdir(dir), 0);
    br_outfile_t o;
    assert_int_equal(br_outfile_open(&o, "test", "rel.txt"), 0);
    fputs("x\n", o.f);
    assert_int_equal(br_outfile_commit(&o, "test"), 0);
    expect("rel.txt", "x\n");
    assert_int_equal(unlink("rel.txt"), 0);
    assert_int_equal(chdir(cwd), 0);
}

static void test_refused_at_open(void **state)
{
    (void)state;
    char path[300];
    br_outfile_t o;
    assert_int_equal(br_outfile_open(&o, "test", dir), -1); /* a directory */
    assert_null(o.f);
    snprintf(path, sizeof path, "%s/no/such/dir/x", dir);
    assert_int_equal(br_outfile_open(&o, "test", path), -1);
    assert_int_equal(br_outfile_open(&o, "test", ""), -1);
    assert_int_equal(br_outfile_open(&o, "test", "/dev/null"), -1); /* never renamed over a device */
    assert_int_equal(others(), 0);
    br_outfile_discard(&o);
}

/* A write that fails (here: past a file-size limit, EFBIG with SIGXFSZ
 * ignored, as a full disk fails) is a failed commit: the destination keeps
 * its old text and the temporary file is removed. The write fails inside
 * fwrite, so only the stream's error flag records it (the final fflush has
 * nothing left to write); then after a failed fflush of buffered text. */
static void test_write_error_fails_commit(void **state)
{
    (void)state;
    char path[300];
    snprintf(path, sizeof path, "%s/keep", dir);
    put(path, "old\n");
    static char big[1 << 16];
    memset(big, 'x', sizeof big);
    struct rlimit old_lim;
    assert_int_equal(getrlimit(RLIMIT_FSIZE, &old_lim), 0);
    void (*old_sig)(int) = signal(SIGXFSZ, SIG_IGN);
    for (int how = 0; how < 2; how++) {
        br_outfile_t o;
        assert_int_equal(br_outfile_open(&o, "test", path), 0);
        struct rlimit lim = {4096, old_lim.rlim_max};
        assert_int_equal(setrlimit(RLIMIT_FSIZE, &lim), 0);
        if (how == 0) {
            assert_true(fwrite(big, 1, sizeof big, o.f) < sizeof big);
            assert_true(ferror(o.f));
        } else {
            /* under one buffer each: the limit is met when the stream flushes */
            for (int k = 0; k < 4; k++) assert_int_equal(fwrite(big, 1, 2000, o.f), 2000);
        }
        const int rc = br_outfile_commit(&o, "test");
        assert_int_equal(setrlimit(RLIMIT_FSIZE, &old_lim), 0);
        assert_int_equal(rc, -1);
        expect(path, "old\n");
        assert_int_equal(others(), 0);
    }
    signal(SIGXFSZ, old_sig);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_discard_keeps_existing, setup, teardown),
        cmocka_unit_test_setup_teardown(test_commit_replaces, setup, teardown),
        cmocka_unit_test_setup_teardown(test_relative_path, setup, teardown),
        cmocka_unit_test_setup_teardown(test_refused_at_open, setup, teardown),
        cmocka_unit_test_setup_teardown(test_write_error_fails_commit, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
