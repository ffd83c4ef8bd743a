/* harness.h - a minimal test harness. Each test binary defines tests with
 * TEST(name) and lists them in main via RUN(name). Every CHECK failure is
 * printed with file:line; the binary prints "N passed, N failed" at the end
 * and exits non-zero when anything failed. */
#ifndef VXL_TEST_HARNESS_H
#define VXL_TEST_HARNESS_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct {
    int failed_checks;
} vxl_test_ctx;

static int vxl_tests_passed, vxl_tests_failed;

#define TEST(name) static void name(vxl_test_ctx *T_)

#define CHECK(cond)                                                                  \
    do {                                                                             \
        if (!(cond)) {                                                               \
            fprintf(stderr, "  %s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
            T_->failed_checks++;                                                     \
        }                                                                            \
    } while (0)

#define CHECKF(cond, ...)                                                   \
    do {                                                                    \
        if (!(cond)) {                                                      \
            fprintf(stderr, "  %s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__);                                   \
            fputc('\n', stderr);                                            \
            T_->failed_checks++;                                            \
        }                                                                   \
    } while (0)

/* Stops the current test (e.g. a handle that later checks need). */
#define REQUIRE(cond)                                                                 \
    do {                                                                              \
        if (!(cond)) {                                                                \
            fprintf(stderr, "  %s:%d: REQUIRE failed: %s\n", __FILE__, __LINE__, #cond); \
            T_->failed_checks++;                                                      \
            return;                                                                   \
        }                                                                             \
    } while (0)

#define RUN(name)                                          \
    do {                                                   \
        vxl_test_ctx ctx_ = {0};                           \
        fprintf(stderr, "[ RUN  ] %s\n", #name);           \
        name(&ctx_);                                       \
        if (ctx_.failed_checks) {                          \
            vxl_tests_failed++;                            \
            fprintf(stderr, "[ FAIL ] %s\n", #name);       \
        } else {                                           \
            vxl_tests_passed++;                            \
            fprintf(stderr, "[  OK  ] %s\n", #name);       \
        }                                                  \
    } while (0)

#define TEST_SUMMARY()                                                   \
    (printf("%d passed, %d failed\n", vxl_tests_passed, vxl_tests_failed), \
     vxl_tests_failed ? 1 : 0)

#endif
