/* What several benchmarks share: process CPU time, a monotonic clock, the load average and a
 * simulation made from a scene text. Header-only: each benchmark is one program (bench/\*.c). */
#ifndef PFSPH_BENCH_UTIL_H
#define PFSPH_BENCH_UTIL_H

#include <stdio.h>
#include <sys/resource.h>
#include <time.h>

#include "pfsph/scene.h"
#include "pfsph/sim.h"

/* CPU time of the process (all threads): on a shared machine it moves less than wall time */
static inline double bench_cpu_seconds(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_sec +
        1e-6 * (double)ru.ru_stime.tv_usec;
}

static inline double bench_wall_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* the 1-minute load average, -1 where /proc/loadavg cannot be read */
static inline double bench_load_average(void)
{
    double l = -1;
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf", &l) != 1) l = -1;
        fclose(f);
    }
    return l;
}

/* A simulation of the scene text json (named name in messages); NULL after printing the
 * parser's or the set-up's message (with the text, which a benchmark generated). */
static inline pfsph_sim *bench_sim_from_json(const char *json, const char *name)
{
    static pfsph_scene s; /* large: not on the stack; the simulation keeps its own copy */
    pfsph_error err = {0};
    if (pfsph_scene_parse(&s, json, name, &err) != PFSPH_OK) {
        fprintf(stderr, "%s\n%s\n", err.msg, json);
        return NULL;
    }
    pfsph_sim *sim = NULL;
    if (pfsph_sim_create(&sim, &s, &err) != PFSPH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return NULL;
    }
    return sim;
}

#endif
