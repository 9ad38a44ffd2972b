/*
 * test_check.h -- the check of the core's C unit tests (test_iwan.c, test_iwan2d.c),
 * plain C99, no framework: a failed check prints its file, line and message and counts
 * in `failures`, which the test returns as its exit status.
 */
#ifndef TEST_CHECK_H
#define TEST_CHECK_H

#include <math.h>
#include <stdio.h>

static int failures = 0;

#define CHECK(cond, ...)                                                   \
    do {                                                                   \
        if (!(cond)) {                                                     \
            ++failures;                                                    \
            printf("FAIL %s:%d: ", __FILE__, __LINE__);                   \
            printf(__VA_ARGS__);                                           \
            printf("\n");                                                  \
        }                                                                  \
    } while (0)

/* |a - b| <= atol + rtol |b| */
static inline int close_to(double a, double b, double rtol, double atol)
{
    return fabs(a - b) <= atol + rtol * fabs(b);
}

#endif /* TEST_CHECK_H */
