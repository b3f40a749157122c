/* C3SampledPd: a foreign FMI 3.0 clocked unit written by hand in plain C against the FMI 3.0 headers that fmpy
 * ships (not built by our exporter), for the clocked engines' tests (tests/foreign_units.py builds it).
 *
 * A single-axis PD law sampled every `period` seconds, its command delivered `delay` seconds after the sample
 * (0 <= delay < period):
 *   sample tick k (t_k = t0 + k period):   e_k = theta_ref - theta,  error = e_k,
 *                                          pending = kp e_k + kd (e_k - e_{k-1}) / period   (e_{-1} = e_0)
 *   delivery tick k (t0 + delay + k period): u = pending
 * Two time-based periodic input clocks of interval variability `fixed` (interval and shift from the
 * parameters, read by the importer with fmi3GetIntervalDecimal / fmi3GetShiftDecimal): sample_clock (vr 100,
 * priority 0, clocks `error`) and delivery_clock (vr 101, priority 1, clocks `u`). At an instant where both tick
 * the sample runs first.
 *
 * Three ways to run it:
 *   - Co-Simulation, eventModeUsed = false (sampled): the unit takes its ticks itself. A tick at the current
 *     time is taken at the first get (from the inputs set then) or at the next fmi3DoStep; fmi3DoStep(t, h)
 *     takes every tick in [t, t + h) in time order with the inputs held.
 *   - Co-Simulation, eventModeUsed = true (clocked): fmi3ExitInitializationMode leads to Event Mode;
 *     fmi3SetClock activates clocks that tick now (else fmi3Error), fmi3UpdateDiscreteStates runs them in
 *     priority order and reports the next tick as nextEventTime; fmi3DoStep refuses a step that passes a tick
 *     not activated.
 *   - Scheduled Execution: fmi3ActivateModelPartition(clock, t) runs the clock's partition at its tick (else
 *     fmi3Error), between the importer's lockPreemption and unlockPreemption callbacks.
 * A tick is "now" within min(1e-10 max(|t|, period), 1e-3 period) of its instant.
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
#ifndef MODEL_TOKEN
#error "MODEL_TOKEN must be defined"
#endif

enum { THETA = 0, THETA_REF = 1, U = 2, ERR = 3, PERIOD = 10, DELAY = 11, KP = 12, KD = 13, NR = 14 };
enum { SAMPLE_CLOCK = 100, DELIVERY_CLOCK = 101 };
typedef enum { INSTANTIATED, INIT, STEP, EVENT, CLOCK_ACTIVATION, TERMINATED } State;

typedef struct {
    fmi3LogMessageCallback log;
    fmi3InstanceEnvironment env;
    fmi3LockPreemptionCallback lock;
    fmi3UnlockPreemptionCallback unlock;
    bool event_mode_used, scheduled, first, active[2];
    State state;
    double t0, time, r[NR], e_prev, pending;
    long long next[2]; /* next tick index of sample_clock, delivery_clock */
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

static double tick(const Instance *c, int i) { return c->t0 + (i ? c->r[DELAY] : 0.0) + c->next[i] * c->r[PERIOD]; }
static double tol(const Instance *c, double t) {
    return fmin(1e-10 * fmax(fabs(t), c->r[PERIOD]), 1e-3 * c->r[PERIOD]);
}
static bool due(const Instance *c, int i, double t) { return fabs(tick(c, i) - t) <= tol(c, t); }

static void run_partition(Instance *c, int i) { /* the clock's partition at its tick */
    if (i == 0) {
        double e = c->r[THETA_REF] - c->r[THETA];
        if (c->first) c->e_prev = e;
        c->first = false;
        c->r[ERR] = e;
        c->pending = c->r[KP] * e + c->r[KD] * (e - c->e_prev) / c->r[PERIOD];
        c->e_prev = e;
    } else {
        c->r[U] = c->pending;
    }
    c->next[i] += 1;
}

/* sampled mode: every tick before `limit` (or at it, within the tolerance, when `inclusive`), in time order */
static void take_ticks(Instance *c, double limit, bool inclusive) {
    for (;;) {
        int i = tick(c, 1) < tick(c, 0) - tol(c, tick(c, 0)) ? 1 : 0; /* the earlier; the sample at a tie */
        double t = tick(c, i);
        if (inclusive ? t > limit + tol(c, limit) : t >= limit - tol(c, limit)) return;
        run_partition(c, i);
    }
}

static Instance *create(fmi3String token, fmi3InstanceEnvironment env, fmi3LogMessageCallback log) {
    Instance *c;
    if (!token || strcmp(token, MODEL_TOKEN) != 0) return NULL;
    c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->env = env;
    c->log = log;
    c->r[PERIOD] = 0.01;
    c->r[KP] = 1.0;
    return c;
}

EXPORT fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
        fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
        fmi3Boolean earlyReturnAllowed, const fmi3ValueReference requiredIntermediateVariables[],
        size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment instanceEnvironment,
        fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate) {
    Instance *c = create(instantiationToken, instanceEnvironment, logMessage);
    (void)instanceName; (void)resourcePath; (void)visible; (void)loggingOn; (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables; (void)nRequiredIntermediateVariables; (void)intermediateUpdate;
    if (c) c->event_mode_used = eventModeUsed;
    return c;
}

EXPORT fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
        fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
        fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate, fmi3LockPreemptionCallback lockPreemption,
        fmi3UnlockPreemptionCallback unlockPreemption) {
    Instance *c = create(instantiationToken, instanceEnvironment, logMessage);
    (void)instanceName; (void)resourcePath; (void)visible; (void)loggingOn; (void)clockUpdate;
    if (c) {
        c->scheduled = true;
        c->lock = lockPreemption;
        c->unlock = unlockPreemption;
    }
    return c;
}

EXPORT fmi3Instance fmi3InstantiateModelExchange(fmi3String a, fmi3String b, fmi3String d, fmi3Boolean e, fmi3Boolean f,
        fmi3InstanceEnvironment g, fmi3LogMessageCallback h) {
    (void)a; (void)b; (void)d; (void)e; (void)f; (void)g; (void)h;
    return NULL; /* Co-Simulation and Scheduled Execution only */
}

EXPORT void fmi3FreeInstance(fmi3Instance instance) { free(instance); }

EXPORT fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined,
        fmi3Float64 tolerance, fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    Instance *c = instance;
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    if (!c || c->state != INSTANTIATED || !isfinite(startTime)) return fmi3Error;
    c->t0 = c->time = startTime;
    c->state = INIT;
    return fmi3OK;
}

EXPORT fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    Instance *c = instance;
    if (!c || c->state != INIT) return fmi3Error;
    if (!(c->r[PERIOD] > 0) || !(c->r[DELAY] >= 0 && c->r[DELAY] < c->r[PERIOD])) {
        logmsg(c, fmi3Error, "fmi3ExitInitializationMode: period %g must be > 0 and delay %g in [0, period)",
               c->r[PERIOD], c->r[DELAY]);
        return fmi3Error;
    }
    c->first = true;
    c->state = c->scheduled ? CLOCK_ACTIVATION : c->event_mode_used ? EVENT : STEP;
    return fmi3OK;
}

EXPORT fmi3Status fmi3Terminate(fmi3Instance instance) {
    Instance *c = instance;
    if (!c) return fmi3Error;
    c->state = TERMINATED;
    return fmi3OK;
}

EXPORT fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Float64 v[],
        size_t nv) {
    Instance *c = instance;
    if (!c || n != nv || (n && (!vr || !v))) return fmi3Error;
    if (c->state == STEP && !c->event_mode_used) take_ticks(c, c->time, true); /* sampled: ticks due now */
    for (size_t k = 0; k < n; k++) {
        if (vr[k] >= NR || (vr[k] > ERR && vr[k] < PERIOD)) {
            logmsg(c, fmi3Error, "fmi3GetFloat64: no variable has value reference %u", (unsigned)vr[k]);
            return fmi3Error;
        }
        v[k] = c->r[vr[k]];
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, const fmi3Float64 v[],
        size_t nv) {
    Instance *c = instance;
    if (!c || n != nv || (n && (!vr || !v)) || c->state == TERMINATED) return fmi3Error;
    for (size_t k = 0; k < n; k++) {
        bool input = vr[k] == THETA || vr[k] == THETA_REF;
        bool param = vr[k] >= PERIOD && vr[k] < NR && (c->state == INSTANTIATED || c->state == INIT);
        if (!(input || param) || !isfinite(v[k])) {
            logmsg(c, fmi3Error, "fmi3SetFloat64: value reference %u cannot be set to %g here", (unsigned)vr[k], v[k]);
            return fmi3Error;
        }
        c->r[vr[k]] = v[k];
    }
    return fmi3OK;
}

static int clock_index(Instance *c, const char *fn, fmi3ValueReference vr) {
    if (vr == SAMPLE_CLOCK || vr == DELIVERY_CLOCK) return (int)(vr - SAMPLE_CLOCK);
    logmsg(c, fmi3Error, "%s: value reference %u is not a clock", fn, (unsigned)vr);
    return -1;
}

EXPORT fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
        fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[]) {
    Instance *c = instance;
    if (!c || c->state == INSTANTIATED) return fmi3Error;
    for (size_t k = 0; k < n; k++) {
        if (clock_index(c, "fmi3GetIntervalDecimal", vr[k]) < 0) return fmi3Error;
        intervals[k] = c->r[PERIOD];
        qualifiers[k] = fmi3IntervalChanged;
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
        fmi3Float64 shifts[]) {
    Instance *c = instance;
    if (!c || c->state == INSTANTIATED) return fmi3Error;
    for (size_t k = 0; k < n; k++) {
        int i = clock_index(c, "fmi3GetShiftDecimal", vr[k]);
        if (i < 0) return fmi3Error;
        shifts[k] = i ? c->r[DELAY] : 0.0;
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, const fmi3Clock v[]) {
    Instance *c = instance;
    if (!c || c->state != EVENT) return fmi3Error;
    for (size_t k = 0; k < n; k++) {
        int i = clock_index(c, "fmi3SetClock", vr[k]);
        if (i < 0) return fmi3Error;
        if (v[k] && !due(c, i, c->time)) {
            logmsg(c, fmi3Error, "fmi3SetClock: clock %u does not tick at t = %.17g (next tick %.17g)",
                   (unsigned)vr[k], c->time, tick(c, i));
            return fmi3Error;
        }
        c->active[i] = v[k];
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *needUpdate, fmi3Boolean *terminate,
        fmi3Boolean *nominalsChanged, fmi3Boolean *valuesChanged, fmi3Boolean *nextDefined, fmi3Float64 *next) {
    Instance *c = instance;
    if (!c || c->state != EVENT || !needUpdate || !terminate || !nominalsChanged || !valuesChanged || !nextDefined ||
        !next)
        return fmi3Error;
    for (int i = 0; i < 2; i++) /* priority order */
        if (c->active[i]) run_partition(c, i);
    c->active[0] = c->active[1] = false;
    *needUpdate = *terminate = *nominalsChanged = *valuesChanged = false;
    *nextDefined = true;
    *next = fmin(tick(c, 0), tick(c, 1));
    return fmi3OK;
}

EXPORT fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    Instance *c = instance;
    if (!c || c->state != STEP || !c->event_mode_used) return fmi3Error;
    c->state = EVENT;
    return fmi3OK;
}

EXPORT fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    Instance *c = instance;
    if (!c || c->state != EVENT) return fmi3Error;
    c->state = STEP;
    return fmi3OK;
}

EXPORT fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 h, fmi3Boolean noSetPrior,
        fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
        fmi3Float64 *lastSuccessfulTime) {
    Instance *c = instance;
    (void)noSetPrior;
    if (!c || c->state != STEP || !(h > 0) || !isfinite(t) || !isfinite(h) || fabs(t - c->time) > tol(c, t))
        return fmi3Error;
    if (c->event_mode_used) {
        for (int i = 0; i < 2; i++)
            if (tick(c, i) < t + h - tol(c, t + h)) {
                logmsg(c, fmi3Error, "fmi3DoStep: the step from %.17g to %.17g passes tick %.17g of clock %d, "
                       "not activated", t, t + h, tick(c, i), SAMPLE_CLOCK + i);
                return fmi3Error;
            }
    } else {
        take_ticks(c, t + h, false);
    }
    c->time = t + h;
    *eventHandlingNeeded = *terminateSimulation = *earlyReturn = false;
    *lastSuccessfulTime = c->time;
    return fmi3OK;
}

EXPORT fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
        fmi3Float64 activationTime) {
    Instance *c = instance;
    int i;
    if (!c || c->state != CLOCK_ACTIVATION) return fmi3Error;
    i = clock_index(c, "fmi3ActivateModelPartition", clockReference);
    if (i < 0) return fmi3Error;
    if (!due(c, i, activationTime)) {
        logmsg(c, fmi3Error, "fmi3ActivateModelPartition: clock %u does not tick at t = %.17g (next tick %.17g)",
               (unsigned)clockReference, activationTime, tick(c, i));
        return fmi3Error;
    }
    if (c->lock) c->lock();
    run_partition(c, i);
    c->time = activationTime;
    if (c->unlock) c->unlock();
    return fmi3OK;
}

/* ----- every other FMI 3.0 function: exported (fmpy binds all of them), refused ---------------------- */
#define REFUSED(NAME) EXPORT fmi3Status NAME(void) { return fmi3Error; }
REFUSED(fmi3Reset) REFUSED(fmi3SetDebugLogging)
REFUSED(fmi3GetFloat32) REFUSED(fmi3GetInt8) REFUSED(fmi3GetUInt8) REFUSED(fmi3GetInt16) REFUSED(fmi3GetUInt16)
REFUSED(fmi3GetInt32) REFUSED(fmi3GetUInt32) REFUSED(fmi3GetInt64) REFUSED(fmi3GetUInt64) REFUSED(fmi3GetBoolean)
REFUSED(fmi3GetString) REFUSED(fmi3GetBinary) REFUSED(fmi3GetClock) REFUSED(fmi3SetFloat32) REFUSED(fmi3SetInt8)
REFUSED(fmi3SetUInt8) REFUSED(fmi3SetInt16) REFUSED(fmi3SetUInt16) REFUSED(fmi3SetInt32) REFUSED(fmi3SetUInt32)
REFUSED(fmi3SetInt64) REFUSED(fmi3SetUInt64) REFUSED(fmi3SetBoolean) REFUSED(fmi3SetString) REFUSED(fmi3SetBinary)
REFUSED(fmi3GetNumberOfVariableDependencies) REFUSED(fmi3GetVariableDependencies) REFUSED(fmi3GetFMUState)
REFUSED(fmi3SetFMUState) REFUSED(fmi3FreeFMUState) REFUSED(fmi3SerializedFMUStateSize)
REFUSED(fmi3SerializeFMUState) REFUSED(fmi3DeserializeFMUState) REFUSED(fmi3GetDirectionalDerivative)
REFUSED(fmi3GetAdjointDerivative) REFUSED(fmi3EnterConfigurationMode) REFUSED(fmi3ExitConfigurationMode)
REFUSED(fmi3GetIntervalFraction) REFUSED(fmi3GetShiftFraction) REFUSED(fmi3SetIntervalDecimal)
REFUSED(fmi3SetIntervalFraction) REFUSED(fmi3SetShiftDecimal) REFUSED(fmi3SetShiftFraction)
REFUSED(fmi3EvaluateDiscreteStates) REFUSED(fmi3GetOutputDerivatives) REFUSED(fmi3EnterContinuousTimeMode)
REFUSED(fmi3CompletedIntegratorStep) REFUSED(fmi3SetTime) REFUSED(fmi3SetContinuousStates)
REFUSED(fmi3GetContinuousStateDerivatives) REFUSED(fmi3GetEventIndicators) REFUSED(fmi3GetContinuousStates)
REFUSED(fmi3GetNominalsOfContinuousStates) REFUSED(fmi3GetNumberOfEventIndicators)
REFUSED(fmi3GetNumberOfContinuousStates)

EXPORT const char *fmi3GetVersion(void) { return "3.0"; }

/* the signatures checked against the standard's function types */
static fmi3InstantiateCoSimulationTYPE *const check_cs = fmi3InstantiateCoSimulation;
static fmi3InstantiateScheduledExecutionTYPE *const check_se = fmi3InstantiateScheduledExecution;
static fmi3SetClockTYPE *const check_clock = fmi3SetClock;
static fmi3GetIntervalDecimalTYPE *const check_interval = fmi3GetIntervalDecimal;
static fmi3GetShiftDecimalTYPE *const check_shift = fmi3GetShiftDecimal;
static fmi3UpdateDiscreteStatesTYPE *const check_update = fmi3UpdateDiscreteStates;
static fmi3DoStepTYPE *const check_step = fmi3DoStep;
static fmi3ActivateModelPartitionTYPE *const check_activate = fmi3ActivateModelPartition;
EXPORT const void *c3_clocked_checks[] = {
    (const void *)check_cs, (const void *)check_se, (const void *)check_clock, (const void *)check_interval,
    (const void *)check_shift, (const void *)check_update, (const void *)check_step, (const void *)check_activate};
