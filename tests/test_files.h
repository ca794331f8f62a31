/* tests/test_files.h — writing the small files tests make for themselves.  Include after
 * cmocka.h. */
#ifndef RS_TESTS_TEST_FILES_H
#define RS_TESTS_TEST_FILES_H

#include <stdio.h>

/* Writes `text` to `path` (failing the test if it cannot). */
static inline void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

/* Removes dir/name (a file a test made in its own temporary folder). */
static inline void remove_in(const char *dir, const char *name)
{
    char p[512];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    remove(p);
}

#endif
