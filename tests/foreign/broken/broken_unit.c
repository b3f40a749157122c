/* BrokenUnit: a small FMI 2.0 Co-Simulation unit written by hand for the tests of `scfmu check`
 * (tests/test_check_broken.py). Healthy (BROKEN == 0) it follows the standard closely; each other
 * variant breaks exactly one thing that one check of the gauntlet is named for:
 *
 *   BROKEN 0  healthy: y = integral of k u dt, a strict state machine, refused bad arguments
 *   BROKEN 1  crash:   fmi2DoStep from t >= FAIL_TIME writes through a NULL pointer (SIGSEGV)
 *   BROKEN 2  hang:    fmi2DoStep from t >= FAIL_TIME never returns
 *   BROKEN 3  nan:     y is NaN once t >= FAIL_TIME, every call still returns fmi2OK
 *   BROKEN 4  lax:     no state checks: every call is accepted in every state
 *   BROKEN 5  leak:    every instance allocates (and touches) LEAK_BYTES that fmi2FreeInstance never frees
 *   BROKEN 6  ends:    not broken: the unit ends its simulation as Stair does: fmi2DoStep from t >= FAIL_TIME
 *                      returns fmi2Discard, every later step fmi2Error (a master stops at the Discard)
 *
 * Value references: k = 0 (parameter, start 1), u = 1 (input, start 1), y = 2 (output, y(0) = 0).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#ifndef MODEL_GUID
#error "MODEL_GUID must be defined"
#endif
#ifndef BROKEN
#define BROKEN 0
#endif
#ifndef FAIL_TIME
#define FAIL_TIME 0.05
#endif
#ifndef LEAK_BYTES
#define LEAK_BYTES (1 << 20)
#endif

enum { ST_INSTANTIATED = 1, ST_INIT = 2, ST_STEP = 4, ST_TERMINATED = 8, ST_ERROR = 16 };
#define ANY (ST_INSTANTIATED | ST_INIT | ST_STEP | ST_TERMINATED | ST_ERROR)

typedef struct {
    fmi2CallbackFunctions cb;
    char *name;
    int state;
    double time, k, u, y;
    int ended;
    void *junk;
} Instance;

static int *volatile crash_target = NULL;

static void logerr(Instance *c, const char *msg) {
    if (c && c->cb.logger) c->cb.logger(c->cb.componentEnvironment, c->name, fmi2Error, "logStatusError", msg);
}

/* 1 when the instance may be used in one of the states of `mask`; logs and fails otherwise */
static int allowed(Instance *c, int mask, const char *fn) {
    if (!c) return 0;
#if BROKEN == 4
    (void)mask; (void)fn;
    return 1;
#else
    if (c->state & mask) return 1;
    logerr(c, fn);
    return 0;
#endif
}

static void defaults(Instance *c) {
    c->time = 0.0;
    c->k = 1.0;
    c->u = 1.0;
    c->y = 0.0;
    c->ended = 0;
}

FMI2_Export const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
FMI2_Export const char *fmi2GetVersion(void) { return fmi2Version; }

FMI2_Export fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean on, size_t n, const fmi2String cats[]) {
    (void)on; (void)n; (void)cats;
    return comp ? fmi2OK : fmi2Error;
}

FMI2_Export fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                                          fmi2String location, const fmi2CallbackFunctions *functions,
                                          fmi2Boolean visible, fmi2Boolean loggingOn) {
    (void)location; (void)visible; (void)loggingOn;
    if (!functions || !instanceName || !fmuGUID || fmuType != fmi2CoSimulation || strcmp(fmuGUID, MODEL_GUID) != 0)
        return NULL;
    Instance *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->cb = *functions;
    c->name = strdup(instanceName);
    c->state = ST_INSTANTIATED;
    defaults(c);
#if BROKEN == 5
    c->junk = malloc(LEAK_BYTES);
    if (c->junk) memset(c->junk, 0x5a, LEAK_BYTES);
#endif
    return c;
}

FMI2_Export void fmi2FreeInstance(fmi2Component comp) {
    Instance *c = comp;
    if (!c) return;
#if BROKEN != 5
    free(c->junk);
#endif
    free(c->name);
    free(c);
}

FMI2_Export fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean tolDefined, fmi2Real tol,
                                           fmi2Real startTime, fmi2Boolean stopDefined, fmi2Real stopTime) {
    (void)tolDefined; (void)tol; (void)stopDefined; (void)stopTime;
    Instance *c = comp;
    if (!allowed(c, ST_INSTANTIATED, "fmi2SetupExperiment: only in Instantiated")) return fmi2Error;
    if (!isfinite(startTime)) { logerr(c, "fmi2SetupExperiment: start time not finite"); return fmi2Error; }
    c->time = startTime;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2EnterInitializationMode(fmi2Component comp) {
    Instance *c = comp;
    if (!allowed(c, ST_INSTANTIATED, "fmi2EnterInitializationMode: only in Instantiated")) return fmi2Error;
    c->state = ST_INIT;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2ExitInitializationMode(fmi2Component comp) {
    Instance *c = comp;
    if (!allowed(c, ST_INIT, "fmi2ExitInitializationMode: only in Initialization Mode")) return fmi2Error;
    c->state = ST_STEP;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2Terminate(fmi2Component comp) {
    Instance *c = comp;
    if (!allowed(c, ST_STEP, "fmi2Terminate: only after initialization")) return fmi2Error;
    c->state = ST_TERMINATED;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2Reset(fmi2Component comp) {
    Instance *c = comp;
    if (!c) return fmi2Error;
    defaults(c);
    c->state = ST_INSTANTIATED;
    return fmi2OK;
}

static double output(const Instance *c) {
#if BROKEN == 3
    if (c->time >= FAIL_TIME - 1e-12) return NAN;
#endif
    return c->y;
}

FMI2_Export fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    Instance *c = comp;
    if (!allowed(c, ST_INIT | ST_STEP | ST_TERMINATED | ST_ERROR, "fmi2GetReal: not before initialization"))
        return fmi2Error;
    if (nvr > 0 && (!vr || !value)) { logerr(c, "fmi2GetReal: NULL array"); return fmi2Error; }
    for (size_t i = 0; i < nvr; i++) {
        switch (vr[i]) {
        case 0: value[i] = c->k; break;
        case 1: value[i] = c->u; break;
        case 2: value[i] = output(c); break;
        default: logerr(c, "fmi2GetReal: unknown value reference"); return fmi2Error;
        }
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                   const fmi2Real value[]) {
    Instance *c = comp;
    if (!allowed(c, ST_INSTANTIATED | ST_INIT | ST_STEP, "fmi2SetReal: not after terminate")) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) { logerr(c, "fmi2SetReal: NULL array"); return fmi2Error; }
    for (size_t i = 0; i < nvr; i++) {
        if (!isfinite(value[i])) { logerr(c, "fmi2SetReal: value not finite"); return fmi2Error; }
        if (fabs(value[i]) > 1e6) { logerr(c, "fmi2SetReal: |value| > 1e6"); return fmi2Error; }
        if (vr[i] == 0) {
            if (!allowed(c, ST_INSTANTIATED | ST_INIT, "fmi2SetReal: k is fixed after initialization")) return fmi2Error;
            c->k = value[i];
        } else if (vr[i] == 1) {
            c->u = value[i];
        } else {
            logerr(c, "fmi2SetReal: value reference cannot be set");
            return fmi2Error;
        }
    }
    return fmi2OK;
}

#define NONE(fn, T)                                                                                \
    FMI2_Export fmi2Status fn(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, T value[]) { \
        (void)vr; (void)value;                                                                     \
        if (!comp) return fmi2Error;                                                               \
        return nvr == 0 ? fmi2OK : fmi2Error;                                                      \
    }
NONE(fmi2GetInteger, fmi2Integer)
NONE(fmi2GetBoolean, fmi2Boolean)
NONE(fmi2GetString, fmi2String)
NONE(fmi2SetInteger, const fmi2Integer)
NONE(fmi2SetBoolean, const fmi2Boolean)
NONE(fmi2SetString, const fmi2String)

FMI2_Export fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
FMI2_Export fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { (void)c; (void)s; return fmi2Error; }
FMI2_Export fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
FMI2_Export fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) {
    (void)c; (void)s; (void)n; return fmi2Error;
}
FMI2_Export fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) {
    (void)c; (void)s; (void)b; (void)n; return fmi2Error;
}
FMI2_Export fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) {
    (void)c; (void)b; (void)n; (void)s; return fmi2Error;
}
FMI2_Export fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                                    const fmi2ValueReference z[], size_t nz, const fmi2Real dv[],
                                                    fmi2Real dz[]) {
    (void)c; (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz; return fmi2Error;
}
FMI2_Export fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                                   const fmi2Integer order[], const fmi2Real value[]) {
    (void)c; (void)vr; (void)nvr; (void)order; (void)value; return fmi2Error;
}
FMI2_Export fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                                    const fmi2Integer order[], fmi2Real value[]) {
    (void)c; (void)vr; (void)nvr; (void)order; (void)value; return fmi2Error;
}

FMI2_Export fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    (void)noSetPrior;
    Instance *c = comp;
    if (!allowed(c, ST_STEP, "fmi2DoStep: only after initialization")) return fmi2Error;
#if BROKEN != 4
    if (!(h > 0.0) || !isfinite(h) || !isfinite(t) || h > 1e6) {
        logerr(c, "fmi2DoStep: the step size must be finite and > 0, the time finite");
        return fmi2Error;
    }
#endif
#if BROKEN == 6
    if (c->ended) {
        logerr(c, "fmi2DoStep: the simulation has ended");
        return fmi2Error;
    }
    if (t >= FAIL_TIME - 1e-12) {
        c->ended = 1;
        return fmi2Discard;
    }
#endif
#if BROKEN == 1
    if (t >= FAIL_TIME - 1e-12) *crash_target = 42;
#elif BROKEN == 2
    if (t >= FAIL_TIME - 1e-12) {
        volatile unsigned long spin = 0;
        for (;;) spin++;
    }
#endif
    c->y += c->k * c->u * h;
    c->time = t + h;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2Error; }
FMI2_Export fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *v) {
    (void)c; (void)s; (void)v; return fmi2Discard;
}
FMI2_Export fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *v) {
    (void)c; (void)s; (void)v; return fmi2Discard;
}
FMI2_Export fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *v) {
    (void)c; (void)s; (void)v; return fmi2Discard;
}
FMI2_Export fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *v) {
    (void)c; (void)s; (void)v; return fmi2Discard;
}
FMI2_Export fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *v) {
    (void)c; (void)s; (void)v; return fmi2Discard;
}
