/* fccqp_now: seconds on the clock Python's time.perf_counter reads, so that a solve's
 * start time taken in Python and the deadlines the compiled core checks (admm, polish)
 * compare: QueryPerformanceCounter on Windows, CLOCK_UPTIME_RAW on macOS (the clock of
 * mach_absolute_time, which perf_counter reads there; CLOCK_MONOTONIC also counts the
 * time asleep), CLOCK_MONOTONIC elsewhere. */
#ifndef FCCQP_CLOCK_H
#define FCCQP_CLOCK_H

#if defined(_WIN32)
#include <windows.h>
static double fccqp_now(void) {
    LARGE_INTEGER count, frequency;
    QueryPerformanceCounter(&count);
    QueryPerformanceFrequency(&frequency);
    return (double)count.QuadPart / (double)frequency.QuadPart;
}
#elif defined(__APPLE__)
#include <time.h>
static double fccqp_now(void) {
    return 1e-9 * (double)clock_gettime_nsec_np(CLOCK_UPTIME_RAW);
}
#else
#include <time.h>
static double fccqp_now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
#endif

#endif
