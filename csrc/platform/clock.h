/* clock.h - a monotonic clock in seconds (clock_posix.c): time limits and
 * the age of cached entries, never the time of day. */
#ifndef VXL_CLOCK_H
#define VXL_CLOCK_H

double vxl_monotonic_s(void);

#endif
