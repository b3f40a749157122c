/* Cost of the Model Exchange calls a solver makes per stage, straight from C (no master around them):
 * fmi2/fmi3 SetTime, SetContinuousStates, GetDerivatives (fmi3GetContinuousStateDerivatives) and
 * CompletedIntegratorStep on one instance in Continuous-Time Mode, each called 2,000,000 times in a row;
 * the best of 7 rounds, in ns per call (docs/benchmarks.md, issue 34).
 *
 *   cc -O2 -o /tmp/me_call_cost benches/me_call_cost.c -ldl
 *   unzip -o -j fmus/AttitudePlant.fmu binaries/linux64/AttitudePlant.so -d /tmp/fmi2
 *   /tmp/me_call_cost 2 /tmp/fmi2/AttitudePlant.so '<guid from modelDescription.xml>' 18
 *   (FMI 3.0: fmus/fmi3/AttitudePlant.fmu, binaries/x86_64-linux/, mode 3, the instantiationToken)
 *
 * Arguments: FMI version (2 or 3), library, GUID / instantiation token, number of continuous states. */
#include <dlfcn.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

typedef void *C;
typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*alloc)(size_t, size_t);
    void (*freem)(void *);
    void *step;
    void *env;
} Callbacks2;
typedef struct {
    int needed, terminate, nominals, values, defined;
    double next;
} EventInfo2;

static void logger2(void *e, const char *n, int s, const char *c, const char *m, ...) {
    va_list a;
    va_start(a, m);
    vfprintf(stderr, m, a);
    fputc('\n', stderr);
    va_end(a);
}
static void logger3(void *e, int s, const char *c, const char *m) { fprintf(stderr, "%s\n", m); }
static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}
static void *sym(void *h, const char *n) {
    void *f = dlsym(h, n);
    if (!f) {
        fprintf(stderr, "missing %s\n", n);
        exit(1);
    }
    return f;
}

int main(int argc, char **argv) {
    if (argc != 5) {
        fprintf(stderr, "usage: %s 2|3 library guid n_states\n", argv[0]);
        return 2;
    }
    int v3 = argv[1][0] == '3';
    size_t nx = (size_t)atoi(argv[4]);
    void *h = dlopen(argv[2], RTLD_NOW | RTLD_LOCAL);
    if (!h || nx == 0 || nx > 64) {
        fprintf(stderr, "%s\n", h ? "n_states must be 1..64" : dlerror());
        return 1;
    }
    C c;
    int st = 0;
    static Callbacks2 cb = {logger2, calloc, free, 0, 0};
    if (v3) {
        c = ((C(*)(const char *, const char *, const char *, bool, bool, void *, void *))sym(h, "fmi3InstantiateModelExchange"))(
            "bench", argv[3], "", false, false, NULL, (void *)logger3);
        if (!c) return 1;
        st |= ((int (*)(C, bool, double, double, bool, double))sym(h, "fmi3EnterInitializationMode"))(c, false, 0, 0, false, 0);
        st |= ((int (*)(C))sym(h, "fmi3ExitInitializationMode"))(c);
        bool more = true, term, nom, val, def;
        double next;
        while (more && st <= 1)
            st |= ((int (*)(C, bool *, bool *, bool *, bool *, bool *, double *))sym(h, "fmi3UpdateDiscreteStates"))(
                c, &more, &term, &nom, &val, &def, &next);
        st |= ((int (*)(C))sym(h, "fmi3EnterContinuousTimeMode"))(c);
    } else {
        c = ((C(*)(const char *, int, const char *, const char *, Callbacks2 *, int, int))sym(h, "fmi2Instantiate"))(
            "bench", 0, argv[3], "", &cb, 0, 0);
        if (!c) return 1;
        st |= ((int (*)(C, int, double, double, int, double))sym(h, "fmi2SetupExperiment"))(c, 0, 0, 0, 0, 0);
        st |= ((int (*)(C))sym(h, "fmi2EnterInitializationMode"))(c);
        st |= ((int (*)(C))sym(h, "fmi2ExitInitializationMode"))(c);
        EventInfo2 ei = {1, 0, 0, 0, 0, 0};
        while (ei.needed && st <= 1) st |= ((int (*)(C, EventInfo2 *))sym(h, "fmi2NewDiscreteStates"))(c, &ei);
        st |= ((int (*)(C))sym(h, "fmi2EnterContinuousTimeMode"))(c);
    }
    double x[64], dx[64];
    st |= ((int (*)(C, double *, size_t))sym(h, v3 ? "fmi3GetContinuousStates" : "fmi2GetContinuousStates"))(c, x, nx);
    if (st > 1) {
        fprintf(stderr, "setup failed (status %d)\n", st);
        return 1;
    }
    int (*set_time)(C, double) = (int (*)(C, double))sym(h, v3 ? "fmi3SetTime" : "fmi2SetTime");
    int (*set_x)(C, const double *, size_t) =
        (int (*)(C, const double *, size_t))sym(h, v3 ? "fmi3SetContinuousStates" : "fmi2SetContinuousStates");
    int (*get_dx)(C, double *, size_t) =
        (int (*)(C, double *, size_t))sym(h, v3 ? "fmi3GetContinuousStateDerivatives" : "fmi2GetDerivatives");
    void *completed = sym(h, v3 ? "fmi3CompletedIntegratorStep" : "fmi2CompletedIntegratorStep");
    const long n = 2000000;
    double best[4] = {1e9, 1e9, 1e9, 1e9};
    for (int r = 0; r < 7; r++) {
        double t[5];
        t[0] = now();
        for (long k = 0; k < n; k++) st |= set_time(c, 1e-9 * (double)k);
        t[1] = now();
        for (long k = 0; k < n; k++) st |= set_x(c, x, nx);
        t[2] = now();
        for (long k = 0; k < n; k++) st |= get_dx(c, dx, nx);
        t[3] = now();
        if (v3) {
            bool e, q;
            for (long k = 0; k < n; k++) st |= ((int (*)(C, bool, bool *, bool *))completed)(c, true, &e, &q);
        } else {
            int e, q;
            for (long k = 0; k < n; k++) st |= ((int (*)(C, int, int *, int *))completed)(c, 1, &e, &q);
        }
        t[4] = now();
        for (int i = 0; i < 4; i++)
            if ((t[i + 1] - t[i]) / n < best[i]) best[i] = (t[i + 1] - t[i]) / n;
    }
    printf("FMI %s.0 (status %d), ns per call: setTime %.1f, setContinuousStates %.1f, getDerivatives %.1f, "
           "completedIntegratorStep %.1f\n",
           v3 ? "3" : "2", st, best[0] * 1e9, best[1] * 1e9, best[2] * 1e9, best[3] * 1e9);
    return st > 1;
}
