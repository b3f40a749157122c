/* Three FMI 3.0 units written by hand in plain C against the FMI 3.0 headers that fmpy ships (foreign units:
 * not built by our exporter), for the engine tests (tests/foreign_units.py builds them):
 *
 * MODEL == 1  C3PdController, Co-Simulation only. The quaternion PD law of PdController (error_law 0):
 *     q_E = conj(q) (x) q_ref,  e = 2 q_E,w q_E,v,  T_i = wn^2 I_i e_i - 2 zeta wn I_i w_i
 *   (outputs evaluated on every get from the inputs then set: direct feedthrough), plus scalar Int32 and
 *   Boolean ports to test Integer and Boolean connections: input `enable` (Boolean, start true; false
 *   zeroes the torque) and `count_in` (Int32); outputs `step_count` (Int32: number of completed doSteps),
 *   `active` (Boolean: step_count even), `count_echo` (= count_in) and `enable_echo` (= enable).
 *
 * MODEL == 2  C3AxisBody, Model Exchange only. A rigid body about one axis:
 *     theta' = omega,  omega' = (sat(u) + torque_dist) / inertia,  sat(u) = clamp(u, -torque_limit, torque_limit)
 *   with one event indicator z = theta - theta_mark (a state event: each sign change is counted in the
 *   Int32 output `crossings`, the first one's time is the output `t_cross`), and one time event at
 *   `kick_time` (if >= 0) where omega jumps by `kick_domega`.
 *
 * MODEL == 3  C3PdControllerME, Model Exchange only: the PD law of MODEL 1 (same inputs, outputs, parameters and
 *   value references, without the Int32/Boolean ports), as a continuous-time controller exported from a
 *   modelling tool would come: no continuous states, no event indicators, no time events; the torque is a
 *   direct feedthrough of the inputs, evaluated on every get in every mode (initialization, event,
 *   continuous-time). The Model Exchange calls an importer makes work on 0 states and 0 indicators.
 *
 * Only the functions these units support do real work; every other FMI 3.0 function is exported (fmpy
 * binds all of them) and returns fmi3Error.
 */
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3PlatformTypes.h"
#include "fmi3FunctionTypes.h"

#define EXPORT __attribute__((visibility("default")))

#ifndef MODEL
#error "MODEL must be 1 (C3PdController), 2 (C3AxisBody) or 3 (C3PdControllerME)"
#endif
#ifndef MODEL_TOKEN
#error "MODEL_TOKEN must be defined"
#endif

#define NV 32
typedef enum { ST_INSTANTIATED, ST_INIT, ST_RUN, ST_EVENT, ST_CONT, ST_TERMINATED } State;

typedef struct {
    fmi3LogMessageCallback log;
    fmi3InstanceEnvironment env;
    State state;
    double time;
    double r[NV];
    int32_t i[NV];
    bool b[NV];
    /* MODEL 2 */
    bool above, kicked;
} Instance;

static void logmsg(Instance *c, fmi3Status st, const char *fmt, ...) {
    char buf[256];
    va_list ap;
    if (!c || !c->log) return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    c->log(c->env, st, "logStatusError", buf);
}

#if MODEL == 1 || MODEL == 3
#define PD_LAW 1
#endif
#if MODEL == 2 || MODEL == 3
#define ME_ONLY 1
#endif

#ifdef PD_LAW
/* value references */
enum { IN0 = 0, N_IN = 14, OUT0 = 14, WN = 17, ZETA = 18, IXX = 19, ENABLE = 22, COUNT_IN = 23, STEP_COUNT = 24,
       ACTIVE = 25, COUNT_ECHO = 26, ENABLE_ECHO = 27 };
static int is_real(fmi3ValueReference v) { return v <= 21; }
static int is_settable_real(fmi3ValueReference v) { return v < OUT0 || (v >= WN && v <= 21); }

static void defaults(Instance *c) {
    c->r[0] = 1.0; c->r[7] = 1.0; /* q_w, q_ref_w */
    c->r[WN] = 1.0; c->r[ZETA] = 1.0; c->r[IXX] = 1000.0; c->r[IXX + 1] = 500.0; c->r[IXX + 2] = 700.0;
    c->b[ENABLE] = true;
}

static double torque(const Instance *c, int k) {
    const double *q = c->r, *w = c->r + 4, *qr = c->r + 7;
    double qc[4] = {q[0], -q[1], -q[2], -q[3]};
    double ew = qc[0] * qr[0] - (qc[1] * qr[1] + qc[2] * qr[2] + qc[3] * qr[3]);
    double cr[3] = {qc[2] * qr[3] - qc[3] * qr[2], qc[3] * qr[1] - qc[1] * qr[3], qc[1] * qr[2] - qc[2] * qr[1]};
    double ev = qc[0] * qr[1 + k] + qr[0] * qc[1 + k] + cr[k];
    double wn = c->r[WN], zeta = c->r[ZETA], in = c->r[IXX + k];
    if (!c->b[ENABLE]) return 0.0;
    return wn * wn * in * (2.0 * ew * ev) - 2.0 * zeta * wn * in * w[k];
}

static fmi3Status get_real(Instance *c, fmi3ValueReference v, double *out) {
    if (!is_real(v)) return fmi3Error;
    *out = (v >= OUT0 && v < OUT0 + 3) ? torque(c, (int)(v - OUT0)) : c->r[v];
    return isfinite(*out) ? fmi3OK : fmi3Error; /* finite inputs can overflow the law: say so, never pass inf on */
}
static fmi3Status set_real(Instance *c, fmi3ValueReference v, double x) {
    if (!is_settable_real(v)) return fmi3Error;
    if (v >= WN && c->state != ST_INIT && c->state != ST_INSTANTIATED) return fmi3Error;
    if (!isfinite(x)) return fmi3Error;
    c->r[v] = x;
    return fmi3OK;
}
#if MODEL == 3 /* no Int32/Boolean ports: every such value reference is refused */
#define NO_DISCRETE_PORTS(v) if (v >= ENABLE) return fmi3Error
#else
#define NO_DISCRETE_PORTS(v) (void)0
#endif
static fmi3Status get_int(Instance *c, fmi3ValueReference v, int32_t *out) {
    NO_DISCRETE_PORTS(v);
    if (v == COUNT_IN || v == STEP_COUNT) { *out = c->i[v]; return fmi3OK; }
    if (v == COUNT_ECHO) { *out = c->i[COUNT_IN]; return fmi3OK; }
    return fmi3Error;
}
static fmi3Status set_int(Instance *c, fmi3ValueReference v, int32_t x) {
    NO_DISCRETE_PORTS(v);
    if (v != COUNT_IN) return fmi3Error;
    c->i[v] = x;
    return fmi3OK;
}
static fmi3Status get_bool(Instance *c, fmi3ValueReference v, bool *out) {
    NO_DISCRETE_PORTS(v);
    if (v == ENABLE || v == ENABLE_ECHO) { *out = c->b[ENABLE]; return fmi3OK; }
    if (v == ACTIVE) { *out = (c->i[STEP_COUNT] % 2) == 0; return fmi3OK; }
    return fmi3Error;
}
static fmi3Status set_bool(Instance *c, fmi3ValueReference v, bool x) {
    NO_DISCRETE_PORTS(v);
    if (v != ENABLE) return fmi3Error;
    c->b[v] = x;
    return fmi3OK;
}
#else
/* value references */
enum { U = 0, TDIST = 1, THETA = 2, OMEGA = 3, APPLIED = 4, THETA_DEG = 5, INERTIA = 6, TLIM = 7, MARK = 8,
       KICK_T = 9, KICK_DW = 10, T_CROSS = 11, DER_THETA = 12, DER_OMEGA = 13, CROSSINGS = 14, Z = 15 };
static void defaults(Instance *c) {
    c->r[INERTIA] = 7.7; c->r[TLIM] = 1.0; c->r[MARK] = 0.1; c->r[KICK_T] = -1.0; c->r[T_CROSS] = -1.0;
}
static double sat(const Instance *c) {
    double u = c->r[U], l = c->r[TLIM];
    return u > l ? l : (u < -l ? -l : u);
}
static fmi3Status get_real(Instance *c, fmi3ValueReference v, double *out) {
    switch (v) {
    case APPLIED: *out = sat(c); return fmi3OK;
    case THETA_DEG: *out = c->r[THETA] * 180.0 / M_PI; return fmi3OK;
    case DER_THETA: *out = c->r[OMEGA]; return fmi3OK;
    case DER_OMEGA: *out = (sat(c) + c->r[TDIST]) / c->r[INERTIA]; return fmi3OK;
    case Z: *out = c->r[THETA] - c->r[MARK]; return fmi3OK;
    default:
        if (v > Z || v == CROSSINGS) return fmi3Error;
        *out = c->r[v];
        return fmi3OK;
    }
}
static fmi3Status set_real(Instance *c, fmi3ValueReference v, double x) {
    /* parameters, and the states' start values (theta, omega), in initialization mode */
    int param = v == INERTIA || v == TLIM || v == MARK || v == KICK_T || v == KICK_DW || v == THETA || v == OMEGA;
    if (!isfinite(x)) return fmi3Error;
    if (v == U || v == TDIST) { c->r[v] = x; return fmi3OK; }
    if (param && (c->state == ST_INIT || c->state == ST_INSTANTIATED)) {
        if (v == INERTIA && !(x > 0)) { logmsg(c, fmi3Error, "fmi3SetFloat64: inertia = %g must be > 0", x); return fmi3Error; }
        c->r[v] = x;
        return fmi3OK;
    }
    return fmi3Error;
}
static fmi3Status get_int(Instance *c, fmi3ValueReference v, int32_t *out) {
    if (v != CROSSINGS) return fmi3Error;
    *out = c->i[CROSSINGS];
    return fmi3OK;
}
static fmi3Status set_int(Instance *c, fmi3ValueReference v, int32_t x) { (void)c; (void)v; (void)x; return fmi3Error; }
static fmi3Status get_bool(Instance *c, fmi3ValueReference v, bool *out) { (void)c; (void)v; (void)out; return fmi3Error; }
static fmi3Status set_bool(Instance *c, fmi3ValueReference v, bool x) { (void)c; (void)v; (void)x; return fmi3Error; }

/* the discrete part: crossings of theta_mark and the kick; returns whether a next time event exists */
static void update(Instance *c, bool *next_defined, double *next) {
    bool above = c->r[THETA] > c->r[MARK];
    if (above != c->above) {
        c->above = above;
        c->i[CROSSINGS] += 1;
        if (c->r[T_CROSS] < 0) c->r[T_CROSS] = c->time;
    }
    if (!c->kicked && c->r[KICK_T] >= 0 && fabs(c->time - c->r[KICK_T]) <= 1e-12 * fmax(1.0, fabs(c->time))) {
        c->r[OMEGA] += c->r[KICK_DW];
        c->kicked = true;
    }
    *next_defined = !c->kicked && c->r[KICK_T] >= c->time;
    *next = *next_defined ? c->r[KICK_T] : 0.0;
}
#endif

/* ----- the Model Exchange units' continuous part: NX states, NZ event indicators ----------------------- */
#if MODEL == 2
#define NX 2
#define NZ 1
static void states_get(const Instance *c, double *x) { x[0] = c->r[THETA]; x[1] = c->r[OMEGA]; }
static void states_set(Instance *c, const double *x) { c->r[THETA] = x[0]; c->r[OMEGA] = x[1]; }
static void derivatives(Instance *c, double *dx) { get_real(c, DER_THETA, &dx[0]); get_real(c, DER_OMEGA, &dx[1]); }
static void indicators(const Instance *c, double *z) { z[0] = c->r[THETA] - c->r[MARK]; }
static void init_discrete(Instance *c) { c->above = c->r[THETA] > c->r[MARK]; }
static void discrete(Instance *c, bool *states_changed, bool *next_defined, double *next) {
    double w0 = c->r[OMEGA];
    update(c, next_defined, next);
    *states_changed = c->r[OMEGA] != w0;
}
#elif MODEL == 3
#define NX 0
#define NZ 0
static void states_get(const Instance *c, double *x) { (void)c; (void)x; }
static void states_set(Instance *c, const double *x) { (void)c; (void)x; }
static void derivatives(Instance *c, double *dx) { (void)c; (void)dx; }
static void indicators(const Instance *c, double *z) { (void)c; (void)z; }
static void init_discrete(Instance *c) { (void)c; }
static void discrete(Instance *c, bool *states_changed, bool *next_defined, double *next) {
    (void)c;
    *states_changed = false;
    *next_defined = false;
    *next = 0.0;
}
#endif

/* ----- the functions this unit supports ------------------------------------------------------------- */
EXPORT const char *fmi3GetVersion(void) { return "3.0"; }
EXPORT fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                                      const fmi3String categories[]) {
    (void)instance; (void)loggingOn; (void)nCategories; (void)categories;
    return fmi3OK;
}

static Instance *create(fmi3String token, fmi3InstanceEnvironment env, fmi3LogMessageCallback log) {
    Instance *c;
    if (!token || strcmp(token, MODEL_TOKEN) != 0) return NULL;
    c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->env = env;
    c->log = log;
    defaults(c);
    return c;
}

EXPORT fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
        fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
        fmi3Boolean earlyReturnAllowed, const fmi3ValueReference requiredIntermediateVariables[],
        size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment instanceEnvironment,
        fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)instanceName; (void)resourcePath; (void)visible; (void)loggingOn; (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables; (void)nRequiredIntermediateVariables; (void)intermediateUpdate;
#ifndef ME_ONLY
    if (eventModeUsed) return NULL;
    return create(instantiationToken, instanceEnvironment, logMessage);
#else
    (void)eventModeUsed; (void)instantiationToken; (void)instanceEnvironment; (void)logMessage;
    return NULL; /* Model Exchange only */
#endif
}

EXPORT fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
        fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
        fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage) {
    (void)instanceName; (void)resourcePath; (void)visible; (void)loggingOn;
#ifdef ME_ONLY
    return create(instantiationToken, instanceEnvironment, logMessage);
#else
    (void)instantiationToken; (void)instanceEnvironment; (void)logMessage;
    return NULL; /* Co-Simulation only */
#endif
}

EXPORT void fmi3FreeInstance(fmi3Instance instance) { free(instance); }

EXPORT fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
        fmi3Float64 tolerance, fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    Instance *c = instance;
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    if (!c || c->state != ST_INSTANTIATED) return fmi3Error;
    c->time = startTime;
    c->state = ST_INIT;
    return fmi3OK;
}

EXPORT fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    Instance *c = instance;
    if (!c || c->state != ST_INIT) return fmi3Error;
#ifndef ME_ONLY
    c->state = ST_RUN;
#else
    init_discrete(c);
    c->state = ST_EVENT;
#endif
    return fmi3OK;
}

EXPORT fmi3Status fmi3Terminate(fmi3Instance instance) {
    Instance *c = instance;
    if (!c) return fmi3Error;
    if (c->state == ST_INSTANTIATED) {
        logmsg(c, fmi3Error, "fmi3Terminate: not allowed before initialization");
        return fmi3Error;
    }
    c->state = ST_TERMINATED;
    return fmi3OK;
}

EXPORT fmi3Status fmi3Reset(fmi3Instance instance) {
    Instance *c = instance;
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log;
    if (!c) return fmi3Error;
    env = c->env;
    log = c->log;
    memset(c, 0, sizeof *c);
    c->env = env;
    c->log = log;
    defaults(c);
    return fmi3OK;
}

/* SETTER: 1 for the fmi3Set* functions (refused after fmi3Terminate) */
#define GETSET(NAME, CT, FN, MODE, SETTER)                                                                  \
    EXPORT fmi3Status NAME(fmi3Instance instance, const fmi3ValueReference vr[], size_t nvr, CT values[],     \
                           size_t nValues) {                                                                \
        Instance *c = instance;                                                                             \
        if (!c || (nvr && (!vr || !values)) || nValues != nvr) return fmi3Error;                            \
        if (SETTER && c->state == ST_TERMINATED) {                                                          \
            logmsg(c, fmi3Error, #NAME ": not allowed after fmi3Terminate");                                \
            return fmi3Error;                                                                               \
        }                                                                                                   \
        for (size_t k = 0; k < nvr; k++)                                                                    \
            if (FN(c, vr[k], MODE values[k]) != fmi3OK) {                                                   \
                logmsg(c, fmi3Error, #NAME ": value reference %u is not allowed here", (unsigned)vr[k]);     \
                return fmi3Error;                                                                           \
            }                                                                                               \
        return fmi3OK;                                                                                      \
    }
GETSET(fmi3GetFloat64, fmi3Float64, get_real, &, 0)
GETSET(fmi3GetInt32, fmi3Int32, get_int, &, 0)
GETSET(fmi3GetBoolean, fmi3Boolean, get_bool, &, 0)
GETSET(fmi3SetFloat64, const fmi3Float64, set_real, , 1)
GETSET(fmi3SetInt32, const fmi3Int32, set_int, , 1)
GETSET(fmi3SetBoolean, const fmi3Boolean, set_bool, , 1)

#if MODEL == 1
EXPORT fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
        fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
        fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
        fmi3Float64 *lastSuccessfulTime) {
    Instance *c = instance;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (!c || c->state != ST_RUN || !(communicationStepSize > 0) || !isfinite(currentCommunicationPoint) ||
        !isfinite(communicationStepSize))
        return fmi3Error;
    c->time = currentCommunicationPoint + communicationStepSize;
    c->i[STEP_COUNT] += 1;
    if (eventHandlingNeeded) *eventHandlingNeeded = false;
    if (terminateSimulation) *terminateSimulation = false;
    if (earlyReturn) *earlyReturn = false;
    if (lastSuccessfulTime) *lastSuccessfulTime = c->time;
    return fmi3OK;
}
#else
EXPORT fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    Instance *c = instance;
    if (!c || c->state != ST_CONT) return fmi3Error;
    c->state = ST_EVENT;
    return fmi3OK;
}
EXPORT fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
        fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
        fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
        fmi3Float64 *nextEventTime) {
    Instance *c = instance;
    bool changed, defined;
    double next;
    if (!c || c->state != ST_EVENT) return fmi3Error;
    discrete(c, &changed, &defined, &next);
    if (discreteStatesNeedUpdate) *discreteStatesNeedUpdate = false;
    if (terminateSimulation) *terminateSimulation = false;
    if (nominalsOfContinuousStatesChanged) *nominalsOfContinuousStatesChanged = false;
    if (valuesOfContinuousStatesChanged) *valuesOfContinuousStatesChanged = changed;
    if (nextEventTimeDefined) *nextEventTimeDefined = defined;
    if (nextEventTime) *nextEventTime = next;
    return fmi3OK;
}
EXPORT fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    Instance *c = instance;
    if (!c || c->state != ST_EVENT) return fmi3Error;
    c->state = ST_CONT;
    return fmi3OK;
}
EXPORT fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
        fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {
    Instance *c = instance;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (!c || c->state != ST_CONT) return fmi3Error;
    if (enterEventMode) *enterEventMode = false;
    if (terminateSimulation) *terminateSimulation = false;
    return fmi3OK;
}
EXPORT fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    Instance *c = instance;
    if (!c) return fmi3Error;
    if (c->state != ST_EVENT && c->state != ST_CONT) {
        logmsg(c, fmi3Error, "fmi3SetTime: allowed in Event and Continuous-Time Mode only");
        return fmi3Error;
    }
    if (!isfinite(time)) {
        logmsg(c, fmi3Error, "fmi3SetTime: time = %g must be finite", time);
        return fmi3Error;
    }
    c->time = time;
    return fmi3OK;
}
/* the vectors' lengths must be NX (states) and NZ (event indicators); with 0, any pointer (NULL too) is fine */
EXPORT fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 x[], size_t n) {
    Instance *c = instance;
    if (!c || n != NX || (n && !x)) return fmi3Error;
    if (c->state != ST_CONT) return fmi3Error; /* Continuous-Time Mode only (FMI 3.0, section 3.2.1) */
    states_set(c, x);
    return fmi3OK;
}
EXPORT fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t n) {
    Instance *c = instance;
    if (!c || n != NX || (n && !x)) return fmi3Error;
    states_get(c, x);
    return fmi3OK;
}
EXPORT fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 dx[], size_t n) {
    Instance *c = instance;
    if (!c || n != NX || (n && !dx)) return fmi3Error;
    if (c->state == ST_INSTANTIATED) return fmi3Error; /* not before Initialization Mode */
    derivatives(c, dx);
    return fmi3OK;
}
EXPORT fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 z[], size_t n) {
    Instance *c = instance;
    if (!c || n != NZ || (n && !z)) return fmi3Error;
    indicators(c, z);
    return fmi3OK;
}
EXPORT fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t n) {
    if (!instance || n != NX || (n && !nominals)) return fmi3Error;
    for (size_t k = 0; k < n; k++) nominals[k] = 1.0;
    return fmi3OK;
}
EXPORT fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *n) {
    if (!instance || !n) return fmi3Error;
    *n = NZ;
    return fmi3OK;
}
EXPORT fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *n) {
    if (!instance || !n) return fmi3Error;
    *n = NX;
    return fmi3OK;
}
#endif

/* ----- every other FMI 3.0 function: exported, refused ---------------------------------------------- */
#define REFUSED(NAME) EXPORT fmi3Status NAME(void) { return fmi3Error; }
REFUSED(fmi3InstantiateScheduledExecution)
REFUSED(fmi3GetFloat32) REFUSED(fmi3GetInt8) REFUSED(fmi3GetUInt8) REFUSED(fmi3GetInt16) REFUSED(fmi3GetUInt16)
REFUSED(fmi3GetUInt32) REFUSED(fmi3GetInt64) REFUSED(fmi3GetUInt64) REFUSED(fmi3GetString) REFUSED(fmi3GetBinary)
REFUSED(fmi3GetClock) REFUSED(fmi3SetFloat32) REFUSED(fmi3SetInt8) REFUSED(fmi3SetUInt8) REFUSED(fmi3SetInt16)
REFUSED(fmi3SetUInt16) REFUSED(fmi3SetUInt32) REFUSED(fmi3SetInt64) REFUSED(fmi3SetUInt64) REFUSED(fmi3SetString)
REFUSED(fmi3SetBinary) REFUSED(fmi3SetClock) REFUSED(fmi3GetNumberOfVariableDependencies)
REFUSED(fmi3GetVariableDependencies) REFUSED(fmi3GetFMUState) REFUSED(fmi3SetFMUState) REFUSED(fmi3FreeFMUState)
REFUSED(fmi3SerializedFMUStateSize) REFUSED(fmi3SerializeFMUState) REFUSED(fmi3DeserializeFMUState)
REFUSED(fmi3GetDirectionalDerivative) REFUSED(fmi3GetAdjointDerivative) REFUSED(fmi3EnterConfigurationMode)
REFUSED(fmi3ExitConfigurationMode) REFUSED(fmi3GetIntervalDecimal) REFUSED(fmi3GetIntervalFraction)
REFUSED(fmi3GetShiftDecimal) REFUSED(fmi3GetShiftFraction) REFUSED(fmi3SetIntervalDecimal)
REFUSED(fmi3SetIntervalFraction) REFUSED(fmi3SetShiftDecimal) REFUSED(fmi3SetShiftFraction)
REFUSED(fmi3EvaluateDiscreteStates) REFUSED(fmi3EnterStepMode) REFUSED(fmi3GetOutputDerivatives)
REFUSED(fmi3ActivateModelPartition)
#if MODEL == 1
REFUSED(fmi3EnterEventMode) REFUSED(fmi3UpdateDiscreteStates) REFUSED(fmi3EnterContinuousTimeMode)
REFUSED(fmi3CompletedIntegratorStep) REFUSED(fmi3SetTime) REFUSED(fmi3SetContinuousStates)
REFUSED(fmi3GetContinuousStateDerivatives) REFUSED(fmi3GetEventIndicators) REFUSED(fmi3GetContinuousStates)
REFUSED(fmi3GetNominalsOfContinuousStates) REFUSED(fmi3GetNumberOfEventIndicators)
REFUSED(fmi3GetNumberOfContinuousStates)
#else
REFUSED(fmi3DoStep)
#endif

/* the implemented functions have the signatures of the FMI 3.0 headers (checked at compile time) */
static fmi3InstantiateCoSimulationTYPE *const check_cs = fmi3InstantiateCoSimulation;
static fmi3InstantiateModelExchangeTYPE *const check_me = fmi3InstantiateModelExchange;
static fmi3GetFloat64TYPE *const check_get = fmi3GetFloat64;
static fmi3SetBooleanTYPE *const check_setb = fmi3SetBoolean;
static fmi3EnterInitializationModeTYPE *const check_init = fmi3EnterInitializationMode;
#if MODEL == 1
static fmi3DoStepTYPE *const check_step = fmi3DoStep;
#else
static fmi3UpdateDiscreteStatesTYPE *const check_update = fmi3UpdateDiscreteStates;
static fmi3CompletedIntegratorStepTYPE *const check_completed = fmi3CompletedIntegratorStep;
static fmi3EnterEventModeTYPE *const check_event = fmi3EnterEventMode;
static fmi3EnterContinuousTimeModeTYPE *const check_cont = fmi3EnterContinuousTimeMode;
static fmi3SetTimeTYPE *const check_time = fmi3SetTime;
static fmi3SetContinuousStatesTYPE *const check_setx = fmi3SetContinuousStates;
static fmi3GetContinuousStatesTYPE *const check_getx = fmi3GetContinuousStates;
static fmi3GetContinuousStateDerivativesTYPE *const check_der = fmi3GetContinuousStateDerivatives;
static fmi3GetEventIndicatorsTYPE *const check_z = fmi3GetEventIndicators;
#endif
EXPORT const void *c3_signature_checks[] = {
    (const void *)check_cs, (const void *)check_me, (const void *)check_get, (const void *)check_setb,
    (const void *)check_init,
#if MODEL == 1
    (const void *)check_step,
#else
    (const void *)check_update, (const void *)check_completed, (const void *)check_event, (const void *)check_cont,
    (const void *)check_time, (const void *)check_setx, (const void *)check_getx, (const void *)check_der,
    (const void *)check_z,
#endif
};
