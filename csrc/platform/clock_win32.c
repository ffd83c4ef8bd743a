/* clock_win32.c - clock.h with the performance counter. */
#include "clock.h"

#include <windows.h>

double vxl_monotonic_s(void)
{
    LARGE_INTEGER f, t;
    QueryPerformanceFrequency(&f);
    QueryPerformanceCounter(&t);
    return (double)t.QuadPart / (double)f.QuadPart;
}
