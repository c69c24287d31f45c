/* sl_test.h — the few assertion macros the unit tests share.
 * A failed check prints file:line and the expression and counts a failure;
 * SL_TEST_END prints "N passed, N failed" and returns non-zero on failure. */
#ifndef SL_TEST_H
#define SL_TEST_H

#include <math.h>
#include <stdio.h>

static int sl_test_passed, sl_test_failed;

#define SL_CHECK(cond) do { \
    if (cond) sl_test_passed++; \
    else { sl_test_failed++; fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); } \
} while (0)

#define SL_CHECK_MSG(cond, ...) do { \
    if (cond) sl_test_passed++; \
    else { sl_test_failed++; fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__, __LINE__, #cond); \
           fprintf(stderr, __VA_ARGS__); fputc('\n', stderr); } \
} while (0)

#define SL_CHECK_NEAR(a, b, tol) SL_CHECK_MSG(fabs((double)(a) - (double)(b)) <= (tol), \
    "%s = %.9g, %s = %.9g, tolerance %g", #a, (double)(a), #b, (double)(b), (double)(tol))

#define SL_TEST_END() do { \
    printf("%d passed, %d failed\n", sl_test_passed, sl_test_failed); \
    return sl_test_failed ? 1 : 0; \
} while (0)

#endif
