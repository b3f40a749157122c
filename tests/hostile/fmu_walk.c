/* fmu_walk: a short, generic walk through any FMI 2.0 or 3.0 binary, for running every FMU we ship under
 * valgrind memcheck (tests/test_check_valgrind.py). Twice: instantiate, initialise with the inputs at their
 * start values, step and read the outputs, take an FMU state, serialize it, restore it into a second
 * instance (deserialize + set), step both, free the states, terminate, free. Model Exchange: instantiate,
 * initialise, event update, continuous-time mode, explicit Euler steps with completedIntegratorStep, FMU
 * state, terminate, free. Exit 0 and "ok <checksum>" when every call returned OK and every output is finite.
 *
 *   fmu_walk 2|3 cs|me LIBRARY TOKEN RESOURCES NSTEPS DT NX STATE(0|1) "in_vr=value,..." "out_vr,..."
 */
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"

static void *lib;
static void *sym(const char *name) {
    void *p = dlsym(lib, name);
    if (!p) { fprintf(stderr, "missing %s\n", name); exit(3); }
    return p;
}
#define F(name) ((name##TYPE *)sym(#name))
#define CHECK(call) do { int s_ = (int)(call); if (s_ > 1) { fprintf(stderr, "%s -> %d (line %d)\n", #call, s_, __LINE__); exit(4); } } while (0)

static void logger2(fmi2ComponentEnvironment env, fmi2String name, fmi2Status st, fmi2String cat, fmi2String msg, ...) {
    (void)env; (void)name; (void)cat;
    if (st > fmi2Warning) fprintf(stderr, "log: %s\n", msg);
}
static void logger3(fmi3InstanceEnvironment env, fmi3Status st, fmi3String cat, fmi3String msg) {
    (void)env; (void)cat;
    if (st > fmi3Warning) fprintf(stderr, "log: %s\n", msg);
}

static unsigned in_vr[512], out_vr[512];
static double in_val[512];
static size_t n_in, n_out;
static double checksum;

static void parse(const char *ins, const char *outs) {
    char *s = strdup(ins), *tok, *save;
    for (tok = strtok_r(s, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(tok, '=');
        in_vr[n_in] = (unsigned)strtoul(tok, NULL, 10);
        in_val[n_in++] = eq ? strtod(eq + 1, NULL) : 0.0;
    }
    free(s);
    s = strdup(outs);
    for (tok = strtok_r(s, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) out_vr[n_out++] = (unsigned)strtoul(tok, NULL, 10);
    free(s);
}

static void finite_all(const double *v, size_t n) {
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(v[i])) { fprintf(stderr, "output %zu not finite\n", i); exit(5); }
        checksum += v[i];
    }
}

/* ---------------------------------------------------------------------------------------- FMI 2.0 */
static fmi2CallbackFunctions cb2 = {logger2, calloc, free, NULL, NULL};

static fmi2Component init2(int me, const char *token, const char *res) {
    fmi2Component c = F(fmi2Instantiate)("walk", me ? fmi2ModelExchange : fmi2CoSimulation, token, res, &cb2,
                                         fmi2False, fmi2False);
    if (!c) { fprintf(stderr, "fmi2Instantiate returned NULL\n"); exit(4); }
    CHECK(F(fmi2SetupExperiment)(c, fmi2False, 0.0, 0.0, fmi2False, 0.0));
    CHECK(F(fmi2EnterInitializationMode)(c));
    if (n_in) CHECK(F(fmi2SetReal)(c, in_vr, n_in, in_val));
    CHECK(F(fmi2ExitInitializationMode)(c));
    if (me) {
        fmi2EventInfo ei;
        do { CHECK(F(fmi2NewDiscreteStates)(c, &ei)); } while (ei.newDiscreteStatesNeeded);
        CHECK(F(fmi2EnterContinuousTimeMode)(c));
    }
    return c;
}

static void step2(fmi2Component c, int me, double t, double dt, size_t nx) {
    double out[512];
    if (!me) {
        CHECK(F(fmi2DoStep)(c, t, dt, fmi2True));
    } else {
        double x[256], dx[256];
        fmi2Boolean enter = 0, term = 0;
        if (nx) {
            CHECK(F(fmi2GetContinuousStates)(c, x, nx));
            CHECK(F(fmi2GetDerivatives)(c, dx, nx));
            for (size_t i = 0; i < nx; i++) x[i] += dt * dx[i];
        }
        CHECK(F(fmi2SetTime)(c, t + dt));
        if (nx) CHECK(F(fmi2SetContinuousStates)(c, x, nx));
        CHECK(F(fmi2CompletedIntegratorStep)(c, fmi2True, &enter, &term));
        if (enter) {
            fmi2EventInfo ei;
            CHECK(F(fmi2EnterEventMode)(c));
            do { CHECK(F(fmi2NewDiscreteStates)(c, &ei)); } while (ei.newDiscreteStatesNeeded);
            CHECK(F(fmi2EnterContinuousTimeMode)(c));
        }
    }
    if (n_out) { CHECK(F(fmi2GetReal)(c, out_vr, n_out, out)); finite_all(out, n_out); }
}

static void walk2(int me, const char *token, const char *res, int nsteps, double dt, size_t nx, int state) {
    fmi2Component a = init2(me, token, res), b = init2(me, token, res);
    double t = 0.0;
    for (int k = 0; k < nsteps / 2; k++, t += dt) step2(a, me, t, dt, nx);
    if (state) {
        fmi2FMUstate s = NULL, s2 = NULL;
        size_t n = 0;
        CHECK(F(fmi2GetFMUstate)(a, &s));
        CHECK(F(fmi2SerializedFMUstateSize)(a, s, &n));
        char *buf = malloc(n);
        CHECK(F(fmi2SerializeFMUstate)(a, s, buf, n));
        CHECK(F(fmi2DeSerializeFMUstate)(b, buf, n, &s2));
        CHECK(F(fmi2SetFMUstate)(b, s2));
        CHECK(F(fmi2SetFMUstate)(a, s)); /* restore onto itself too */
        CHECK(F(fmi2FreeFMUstate)(a, &s));
        CHECK(F(fmi2FreeFMUstate)(b, &s2));
        free(buf);
    }
    double tb = state ? t : 0.0;
    for (int k = nsteps / 2; k < nsteps; k++, t += dt, tb += dt) { step2(a, me, t, dt, nx); step2(b, me, tb, dt, nx); }
    CHECK(F(fmi2Terminate)(a));
    CHECK(F(fmi2Terminate)(b));
    F(fmi2FreeInstance)(a);
    F(fmi2FreeInstance)(b);
}

/* ---------------------------------------------------------------------------------------- FMI 3.0 */
static fmi3Instance init3(int me, const char *token, const char *res) {
    fmi3Instance c = me ? F(fmi3InstantiateModelExchange)("walk", token, res, fmi3False, fmi3False, NULL, logger3)
                        : F(fmi3InstantiateCoSimulation)("walk", token, res, fmi3False, fmi3False, fmi3False,
                                                         fmi3False, NULL, 0, NULL, logger3, NULL);
    if (!c) { fprintf(stderr, "fmi3Instantiate returned NULL\n"); exit(4); }
    CHECK(F(fmi3EnterInitializationMode)(c, fmi3False, 0.0, 0.0, fmi3False, 0.0));
    if (n_in) CHECK(F(fmi3SetFloat64)(c, in_vr, n_in, in_val, n_in));
    CHECK(F(fmi3ExitInitializationMode)(c));
    if (me) {
        fmi3Boolean need = 1, term, nom, val, def;
        fmi3Float64 next;
        while (need) CHECK(F(fmi3UpdateDiscreteStates)(c, &need, &term, &nom, &val, &def, &next));
        CHECK(F(fmi3EnterContinuousTimeMode)(c));
    }
    return c;
}

static void step3(fmi3Instance c, int me, double t, double dt, size_t nx) {
    double out[512];
    if (!me) {
        fmi3Boolean ev, term, early;
        fmi3Float64 last;
        CHECK(F(fmi3DoStep)(c, t, dt, fmi3True, &ev, &term, &early, &last));
    } else {
        double x[256], dx[256];
        fmi3Boolean enter = 0, term = 0;
        if (nx) {
            CHECK(F(fmi3GetContinuousStates)(c, x, nx));
            CHECK(F(fmi3GetContinuousStateDerivatives)(c, dx, nx));
            for (size_t i = 0; i < nx; i++) x[i] += dt * dx[i];
        }
        CHECK(F(fmi3SetTime)(c, t + dt));
        if (nx) CHECK(F(fmi3SetContinuousStates)(c, x, nx));
        CHECK(F(fmi3CompletedIntegratorStep)(c, fmi3True, &enter, &term));
        if (enter) {
            fmi3Boolean need = 1, tm, nom, val, def;
            fmi3Float64 next;
            CHECK(F(fmi3EnterEventMode)(c));
            while (need) CHECK(F(fmi3UpdateDiscreteStates)(c, &need, &tm, &nom, &val, &def, &next));
            CHECK(F(fmi3EnterContinuousTimeMode)(c));
        }
    }
    if (n_out) { CHECK(F(fmi3GetFloat64)(c, out_vr, n_out, out, n_out)); finite_all(out, n_out); }
}

static void walk3(int me, const char *token, const char *res, int nsteps, double dt, size_t nx, int state) {
    fmi3Instance a = init3(me, token, res), b = init3(me, token, res);
    double t = 0.0;
    for (int k = 0; k < nsteps / 2; k++, t += dt) step3(a, me, t, dt, nx);
    if (state) {
        fmi3FMUState s = NULL, s2 = NULL;
        size_t n = 0;
        CHECK(F(fmi3GetFMUState)(a, &s));
        CHECK(F(fmi3SerializedFMUStateSize)(a, s, &n));
        fmi3Byte *buf = malloc(n);
        CHECK(F(fmi3SerializeFMUState)(a, s, buf, n));
        CHECK(F(fmi3DeserializeFMUState)(b, buf, n, &s2));
        CHECK(F(fmi3SetFMUState)(b, s2));
        CHECK(F(fmi3SetFMUState)(a, s));
        CHECK(F(fmi3FreeFMUState)(a, &s));
        CHECK(F(fmi3FreeFMUState)(b, &s2));
        free(buf);
    }
    double tb = state ? t : 0.0;
    for (int k = nsteps / 2; k < nsteps; k++, t += dt, tb += dt) { step3(a, me, t, dt, nx); step3(b, me, tb, dt, nx); }
    CHECK(F(fmi3Terminate)(a));
    CHECK(F(fmi3Terminate)(b));
    F(fmi3FreeInstance)(a);
    F(fmi3FreeInstance)(b);
}

int main(int argc, char **argv) {
    if (argc != 12) {
        fprintf(stderr, "usage: fmu_walk 2|3 cs|me LIBRARY TOKEN RESOURCES NSTEPS DT NX STATE INPUTS OUTPUTS\n");
        return 2;
    }
    int version = atoi(argv[1]), me = strcmp(argv[2], "me") == 0;
    int nsteps = atoi(argv[6]), state = atoi(argv[9]);
    double dt = strtod(argv[7], NULL);
    size_t nx = (size_t)atoi(argv[8]);
    if (nx > 256) { fprintf(stderr, "too many states\n"); return 2; }
    parse(argv[10], argv[11]);
    lib = dlopen(argv[3], RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 3; }
    for (int rep = 0; rep < 2; rep++) {
        if (version == 2) walk2(me, argv[4], argv[5], nsteps, dt, nx, state);
        else walk3(me, argv[4], argv[5], nsteps, dt, nx, state);
    }
    dlclose(lib);
    printf("ok %.17g\n", checksum);
    return 0;
}
