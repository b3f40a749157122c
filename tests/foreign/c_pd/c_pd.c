/* CPdController: a quaternion PD attitude controller written by hand in plain C against the FMI 2.0
 * headers that fmpy ships, as a "foreign" unit (not built by our exporter) for the bring-your-own-unit tests.
 *
 *   q_E = conj(q) (x) q_ref,  e = 2 q_E,w q_E,v,  T_i = k_i e_i + k_d,i w_i,
 *   k_i = wn^2 I_i,  k_d,i = -2 zeta wn I_i          (PdController with error_law = 0, gain_mode = 0)
 *
 * The outputs are evaluated on every fmi2GetReal from the inputs then set (direct feedthrough), like ours.
 * Its value references are its own (parameters 1-5, inputs 10-23, outputs 30-32): masters must go by name.
 *
 * Compile-time options (tests/foreign_units.py sets them per variant):
 *   MODEL_GUID       the GUID of the modelDescription (checked in fmi2Instantiate)
 *   FAIL_MODE        0 ok, 1 crash (SIGSEGV in fmi2DoStep), 2 hang (endless loop in fmi2DoStep),
 *                    3 NaN outputs, 4 fmi2DoStep returns fmi2Error with a logged message
 *   FAIL_TIME        the model time from which the failure happens (s): the fmi2DoStep that starts at
 *                    t >= FAIL_TIME crashes / hangs / fails; outputs are NaN once the instance time >= FAIL_TIME
 *   MODEL_EXCHANGE   1: the unit is instantiated as Model Exchange only (fmi2Instantiate refuses
 *                    fmi2CoSimulation) and implements the Model Exchange functions for its 0 continuous states
 *                    and 0 event indicators: the PD law as a continuous-time controller with direct
 *                    feedthrough, evaluated on every fmi2GetReal in initialization, event and continuous-time
 *                    mode. 0 (default): Co-Simulation only; the Model Exchange functions are not in the binary
 *                    (the "me_only" variant declares Model Exchange anyway, to test that masters refuse it).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#ifndef MODEL_GUID
#error "MODEL_GUID must be defined"
#endif
#ifndef FAIL_MODE
#define FAIL_MODE 0
#endif
#ifndef FAIL_TIME
#define FAIL_TIME 0.5
#endif
#ifndef MODEL_EXCHANGE
#define MODEL_EXCHANGE 0
#endif
#if MODEL_EXCHANGE
#define UNIT_TYPE fmi2ModelExchange
#define UNIT_TYPE_TEXT "fmi2Instantiate: only Model Exchange is supported"
#else
#define UNIT_TYPE fmi2CoSimulation
#define UNIT_TYPE_TEXT "fmi2Instantiate: only Co-Simulation is supported"
#endif

/* value references */
enum { VR_WN = 1, VR_ZETA = 2, VR_IXX = 3, VR_IYY = 4, VR_IZZ = 5 };
enum { VR_IN0 = 10, N_IN = 14 };   /* q_w q_x q_y q_z w_x w_y w_z q_ref_w..z w_ref_x..z */
enum { VR_OUT0 = 30, N_OUT = 3 };  /* torque_cmd_x _y _z */

/* ST_STEP: Co-Simulation step mode; ST_EVENT, ST_CONT: Model Exchange event and continuous-time modes */
typedef enum { ST_INSTANTIATED, ST_INIT, ST_STEP, ST_EVENT, ST_CONT, ST_TERMINATED, ST_ERROR } State;

typedef struct {
    fmi2CallbackFunctions cb;
    char *name;
    fmi2Boolean logging;
    State state;
    double time;
    double wn, zeta, inertia[3];
    double in[N_IN];
} Instance;

/* read by the crash variant: the compiler cannot prove it NULL, so the store is a real memory fault */
static int *volatile crash_target = NULL;

static void logmsg(Instance *c, fmi2Status status, const char *category, const char *fmt, ...) {
    char buf[512];
    va_list ap;
    if (!c || !c->cb.logger) return;
    if (status == fmi2OK && !c->logging) return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    /* the message goes as the format string with no arguments: masters such as fmpy cannot expand C
     * varargs. A '%' would be read as a conversion by the masters that do, so none is passed on. */
    for (char *p = buf; *p; p++)
        if (*p == '%') *p = '#';
    c->cb.logger(c->cb.componentEnvironment, c->name, status, category, buf);
}

static void set_defaults(Instance *c) {
    static const double in0[N_IN] = {1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0};
    c->time = 0.0;
    c->wn = 1.0;
    c->zeta = 1.0;
    c->inertia[0] = 1000.0;
    c->inertia[1] = 500.0;
    c->inertia[2] = 700.0;
    memcpy(c->in, in0, sizeof in0);
}

/* the PD law: torque from the current inputs and parameters */
static void pd_torque(const Instance *c, double t[3]) {
    const double *q = c->in, *w = c->in + 4, *r = c->in + 7;
    /* q_E = conj(q) (x) r, conj(q) = (q0, -qv) */
    double a0 = q[0], ax = -q[1], ay = -q[2], az = -q[3];
    double ew = a0 * r[0] - ax * r[1] - ay * r[2] - az * r[3];
    double ex = a0 * r[1] + r[0] * ax + (ay * r[3] - az * r[2]);
    double ey = a0 * r[2] + r[0] * ay + (az * r[1] - ax * r[3]);
    double ez = a0 * r[3] + r[0] * az + (ax * r[2] - ay * r[1]);
    double e[3] = {2.0 * ew * ex, 2.0 * ew * ey, 2.0 * ew * ez};
    for (int i = 0; i < 3; i++) {
        double k = c->wn * c->wn * c->inertia[i];
        double kd = c->inertia[i] * (-2.0 * c->zeta * c->wn);
        t[i] = k * e[i] + kd * w[i];
    }
#if FAIL_MODE == 3
    if (c->time >= FAIL_TIME - 1e-12)
        for (int i = 0; i < 3; i++) t[i] = NAN;
#endif
}

static int bad_instance(Instance *c, const char *fn) {
    if (!c) return 1;
    if (c->state == ST_ERROR) {
        logmsg(c, fmi2Error, "logStatusError", "%s: the instance is in the error state", fn);
        return 1;
    }
    return 0;
}

/* ---------------------------------------------------------------- common functions */

FMI2_Export const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
FMI2_Export const char *fmi2GetVersion(void) { return fmi2Version; }

FMI2_Export fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean loggingOn, size_t n,
                                           const fmi2String categories[]) {
    (void)n; (void)categories;
    Instance *c = comp;
    if (!c) return fmi2Error;
    c->logging = loggingOn;
    return fmi2OK;
}

FMI2_Export fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                                          fmi2String fmuResourceLocation,
                                          const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                                          fmi2Boolean loggingOn) {
    (void)fmuResourceLocation; (void)visible;
    if (!functions) return NULL;
    if (fmuType != UNIT_TYPE || !fmuGUID || strcmp(fmuGUID, MODEL_GUID) != 0) {
        if (functions->logger)
            functions->logger(functions->componentEnvironment, instanceName ? instanceName : "?", fmi2Error,
                              "logStatusError",
                              fmuType != UNIT_TYPE ? UNIT_TYPE_TEXT
                                                   : "fmi2Instantiate: GUID does not match the modelDescription");
        return NULL;
    }
    Instance *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->cb = *functions;
    c->name = strdup(instanceName ? instanceName : "CPdController");
    c->logging = loggingOn;
    c->state = ST_INSTANTIATED;
    set_defaults(c);
    return c;
}

FMI2_Export void fmi2FreeInstance(fmi2Component comp) {
    Instance *c = comp;
    if (!c) return;
    free(c->name);
    free(c);
}

FMI2_Export fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean toleranceDefined,
                                           fmi2Real tolerance, fmi2Real startTime,
                                           fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    Instance *c = comp;
    if (bad_instance(c, "fmi2SetupExperiment")) return fmi2Error;
    c->time = startTime;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2EnterInitializationMode(fmi2Component comp) {
    Instance *c = comp;
    if (bad_instance(c, "fmi2EnterInitializationMode")) return fmi2Error;
    c->state = ST_INIT;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2ExitInitializationMode(fmi2Component comp) {
    Instance *c = comp;
    if (bad_instance(c, "fmi2ExitInitializationMode")) return fmi2Error;
    if (!(c->wn > 0.0) || !(c->zeta >= 0.0) || !(c->inertia[0] > 0.0) || !(c->inertia[1] > 0.0) ||
        !(c->inertia[2] > 0.0)) {
        logmsg(c, fmi2Error, "logStatusError", "fmi2ExitInitializationMode: wn, inertia must be > 0, zeta >= 0");
        c->state = ST_ERROR;
        return fmi2Error;
    }
    c->state = MODEL_EXCHANGE ? ST_EVENT : ST_STEP; /* Model Exchange: initialization ends in event mode */
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2Terminate(fmi2Component comp) {
    Instance *c = comp;
    if (!c) return fmi2Error;
    c->state = ST_TERMINATED;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2Reset(fmi2Component comp) {
    Instance *c = comp;
    if (!c) return fmi2Error;
    set_defaults(c);
    c->state = ST_INSTANTIATED;
    return fmi2OK;
}

/* ---------------------------------------------------------------- getters and setters */

FMI2_Export fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                   fmi2Real value[]) {
    Instance *c = comp;
    double t[3];
    if (bad_instance(c, "fmi2GetReal")) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return fmi2Error;
    pd_torque(c, t);
    for (size_t i = 0; i < nvr; i++) {
        fmi2ValueReference r = vr[i];
        if (r == VR_WN) value[i] = c->wn;
        else if (r == VR_ZETA) value[i] = c->zeta;
        else if (r >= VR_IXX && r <= VR_IZZ) value[i] = c->inertia[r - VR_IXX];
        else if (r >= VR_IN0 && r < VR_IN0 + N_IN) value[i] = c->in[r - VR_IN0];
        else if (r >= VR_OUT0 && r < VR_OUT0 + N_OUT) value[i] = t[r - VR_OUT0];
        else {
            logmsg(c, fmi2Error, "logStatusError", "fmi2GetReal: unknown value reference %u", (unsigned)r);
            return fmi2Error;
        }
    }
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                   const fmi2Real value[]) {
    Instance *c = comp;
    if (bad_instance(c, "fmi2SetReal")) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return fmi2Error;
    for (size_t i = 0; i < nvr; i++) {
        fmi2ValueReference r = vr[i];
        int is_param = r >= VR_WN && r <= VR_IZZ;
        if (is_param && c->state != ST_INSTANTIATED && c->state != ST_INIT) {
            logmsg(c, fmi2Error, "logStatusError",
                   "fmi2SetReal: parameter %u is fixed after initialization", (unsigned)r);
            return fmi2Error;
        }
        if (r == VR_WN) c->wn = value[i];
        else if (r == VR_ZETA) c->zeta = value[i];
        else if (r >= VR_IXX && r <= VR_IZZ) c->inertia[r - VR_IXX] = value[i];
        else if (r >= VR_IN0 && r < VR_IN0 + N_IN) c->in[r - VR_IN0] = value[i];
        else {
            logmsg(c, fmi2Error, "logStatusError", "fmi2SetReal: value reference %u cannot be set",
                   (unsigned)r);
            return fmi2Error;
        }
    }
    return fmi2OK;
}

/* no Integer, Boolean or String variables: only empty calls succeed */
#define NO_VARIABLES(fn, T)                                                                        \
    FMI2_Export fmi2Status fn(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, T value[]) { \
        (void)vr; (void)value;                                                                     \
        Instance *c = comp;                                                                        \
        if (bad_instance(c, #fn)) return fmi2Error;                                                \
        if (nvr == 0) return fmi2OK;                                                               \
        logmsg(c, fmi2Error, "logStatusError", #fn ": unknown value reference %u", (unsigned)vr[0]); \
        return fmi2Error;                                                                          \
    }
NO_VARIABLES(fmi2GetInteger, fmi2Integer)
NO_VARIABLES(fmi2GetBoolean, fmi2Boolean)
NO_VARIABLES(fmi2GetString, fmi2String)
NO_VARIABLES(fmi2SetInteger, const fmi2Integer)
NO_VARIABLES(fmi2SetBoolean, const fmi2Boolean)
NO_VARIABLES(fmi2SetString, const fmi2String)

/* ---------------------------------------------------------------- FMU state: not supported */

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
                                                    const fmi2ValueReference z[], size_t nz,
                                                    const fmi2Real dv[], fmi2Real dz[]) {
    (void)c; (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz; return fmi2Error;
}

/* ---------------------------------------------------------------- Co-Simulation */

FMI2_Export fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                                   const fmi2Integer order[], const fmi2Real value[]) {
    (void)c; (void)vr; (void)nvr; (void)order; (void)value; return fmi2Error;
}
FMI2_Export fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                                    const fmi2Integer order[], fmi2Real value[]) {
    (void)c; (void)vr; (void)nvr; (void)order; (void)value; return fmi2Error;
}

FMI2_Export fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real currentCommunicationPoint,
                                  fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    Instance *c = comp;
    if (bad_instance(c, "fmi2DoStep")) return fmi2Error;
    if (c->state != ST_STEP) {
        logmsg(c, fmi2Error, "logStatusError", "fmi2DoStep: not in step mode");
        return fmi2Error;
    }
    if (!(communicationStepSize > 0.0)) {
        logmsg(c, fmi2Error, "logStatusError", "fmi2DoStep: step size %g must be > 0", communicationStepSize);
        return fmi2Error;
    }
#if FAIL_MODE == 1 || FAIL_MODE == 2 || FAIL_MODE == 4
    if (currentCommunicationPoint >= FAIL_TIME - 1e-12) {
#if FAIL_MODE == 1
        *crash_target = 42; /* SIGSEGV */
#elif FAIL_MODE == 2
        volatile unsigned long spin = 0;
        for (;;) spin++;
#else
        logmsg(c, fmi2Error, "logStatusError", "CPdController: deliberate failure at t = %g (variant error)",
               currentCommunicationPoint);
        c->state = ST_ERROR;
        return fmi2Error;
#endif
    }
#endif
    c->time = currentCommunicationPoint + communicationStepSize;
    return fmi2OK;
}

FMI2_Export fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2Error; }

FMI2_Export fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)c; (void)s; (void)value; return fmi2Discard;
}
FMI2_Export fmi2Status fmi2GetRealStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Real *value) {
    Instance *c = comp;
    if (!c || !value || s != fmi2LastSuccessfulTime) return fmi2Discard;
    *value = c->time;
    return fmi2OK;
}
FMI2_Export fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)c; (void)s; (void)value; return fmi2Discard;
}
FMI2_Export fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    (void)c; (void)s; (void)value; return fmi2Discard;
}
FMI2_Export fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)c; (void)s; (void)value; return fmi2Discard;
}

/* ---------------------------------------------------------------- Model Exchange (MODEL_EXCHANGE = 1) */
#if MODEL_EXCHANGE
static fmi2Status in_mode(Instance *c, const char *fn, int ok) {
    if (bad_instance(c, fn)) return fmi2Error;
    if (!ok) {
        logmsg(c, fmi2Error, "logStatusError", "%s: not allowed in this mode", fn);
        return fmi2Error;
    }
    return fmi2OK;
}
FMI2_Export fmi2Status fmi2EnterEventMode(fmi2Component comp) {
    Instance *c = comp;
    if (in_mode(c, "fmi2EnterEventMode", c && (c->state == ST_CONT || c->state == ST_EVENT)) != fmi2OK) return fmi2Error;
    c->state = ST_EVENT;
    return fmi2OK;
}
FMI2_Export fmi2Status fmi2NewDiscreteStates(fmi2Component comp, fmi2EventInfo *info) {
    Instance *c = comp;
    if (in_mode(c, "fmi2NewDiscreteStates", c && c->state == ST_EVENT) != fmi2OK || !info) return fmi2Error;
    info->newDiscreteStatesNeeded = fmi2False;
    info->terminateSimulation = fmi2False;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    info->valuesOfContinuousStatesChanged = fmi2False;
    info->nextEventTimeDefined = fmi2False;
    info->nextEventTime = 0.0;
    return fmi2OK;
}
FMI2_Export fmi2Status fmi2EnterContinuousTimeMode(fmi2Component comp) {
    Instance *c = comp;
    if (in_mode(c, "fmi2EnterContinuousTimeMode", c && c->state == ST_EVENT) != fmi2OK) return fmi2Error;
    c->state = ST_CONT;
    return fmi2OK;
}
FMI2_Export fmi2Status fmi2CompletedIntegratorStep(fmi2Component comp, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                                   fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation) {
    Instance *c = comp;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (in_mode(c, "fmi2CompletedIntegratorStep", c && c->state == ST_CONT) != fmi2OK) return fmi2Error;
    if (enterEventMode) *enterEventMode = fmi2False;
    if (terminateSimulation) *terminateSimulation = fmi2False;
    return fmi2OK;
}
FMI2_Export fmi2Status fmi2SetTime(fmi2Component comp, fmi2Real time) {
    Instance *c = comp;
    if (bad_instance(c, "fmi2SetTime")) return fmi2Error;
    c->time = time;
    return fmi2OK;
}
/* 0 continuous states, 0 event indicators: only empty vectors (any pointer) are accepted */
#define EMPTY_VECTOR(fn, T)                                                                              \
    FMI2_Export fmi2Status fn(fmi2Component comp, T x[], size_t n) {                                     \
        Instance *c = comp;                                                                              \
        (void)x;                                                                                         \
        if (bad_instance(c, #fn)) return fmi2Error;                                                      \
        if (n == 0) return fmi2OK;                                                                       \
        logmsg(c, fmi2Error, "logStatusError", #fn ": %u elements asked, the unit has 0", (unsigned)n);  \
        return fmi2Error;                                                                                \
    }
EMPTY_VECTOR(fmi2SetContinuousStates, const fmi2Real)
EMPTY_VECTOR(fmi2GetContinuousStates, fmi2Real)
EMPTY_VECTOR(fmi2GetDerivatives, fmi2Real)
EMPTY_VECTOR(fmi2GetEventIndicators, fmi2Real)
EMPTY_VECTOR(fmi2GetNominalsOfContinuousStates, fmi2Real)

/* the Model Exchange functions have the signatures of the FMI 2.0 headers (checked at compile time) */
static fmi2NewDiscreteStatesTYPE *const check_nds = fmi2NewDiscreteStates;
static fmi2CompletedIntegratorStepTYPE *const check_cis = fmi2CompletedIntegratorStep;
static fmi2SetContinuousStatesTYPE *const check_setx = fmi2SetContinuousStates;
static fmi2GetDerivativesTYPE *const check_der = fmi2GetDerivatives;
static fmi2GetEventIndicatorsTYPE *const check_z = fmi2GetEventIndicators;
static fmi2GetNominalsOfContinuousStatesTYPE *const check_nom = fmi2GetNominalsOfContinuousStates;
FMI2_Export const void *c_pd_me_signature_checks[] = {(const void *)check_nds, (const void *)check_cis,
                                                       (const void *)check_setx, (const void *)check_der,
                                                       (const void *)check_z, (const void *)check_nom};
#endif
