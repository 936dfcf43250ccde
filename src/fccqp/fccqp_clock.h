/* fccqp_now: seconds on a monotonic clock, QueryPerformanceCounter on Windows and
 * CLOCK_MONOTONIC elsewhere: on Linux and Windows the clock Python's time.perf_counter
 * reads, so that a solve's start time taken in Python and the deadlines the compiled core
 * checks (admm, polish) compare. */
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
