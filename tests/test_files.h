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

#endif
