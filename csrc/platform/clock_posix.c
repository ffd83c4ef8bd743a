/* clock_posix.c - clock.h with CLOCK_MONOTONIC. */
#include "clock.h"

#include <time.h>

double vxl_monotonic_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + t.tv_nsec * 1e-9;
}
