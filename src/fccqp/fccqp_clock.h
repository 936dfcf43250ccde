/* fccqp_now: seconds on the clock Python's time.perf_counter reads (QueryPerformanceCounter
 * on Windows, CLOCK_MONOTONIC elsewhere), so that a solve's start time taken in Python
 * and its deadlines checked in the compiled core compare. */
#ifndef FCCQP_CLOCK_H
#define FCCQP_CLOCK_H

#ifdef _WIN32
#include <windows.h>
static double fccqp_now(void) {
    LARGE_INTEGER count, frequency;
    QueryPerformanceCounter(&count);
    QueryPerformanceFrequency(&frequency);
    return (double)count.QuadPart / (double)frequency.QuadPart;
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
