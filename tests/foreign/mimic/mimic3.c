/* Mimic3: small FMI 3.0 units written by hand for tests/test_check_mimic.py. Each variant behaves, in the one
 * respect named, the way a Modelica Reference-FMU does (its behaviour observed, and read in their source; none
 * of their code is used here), so that the checker's verdict on such behaviour is tested on a unit of ours:
 *
 *   MIMIC 1  discrete input (like Feedthrough, ME): a discrete Float64 input `d` may be set only in
 *            Instantiated, Initialization and Event Mode; fmi3SetFloat64 on it in Continuous-Time Mode is
 *            refused. y = u (continuous input), yd = d.
 *   MIMIC 2  the unit ends the simulation (like Stair, CS and ME): a counter that counts every 0.1 s up to 5,
 *            then terminateSimulation (fmi3DoStep's flag; fmi3UpdateDiscreteStates' flag); a step or an event
 *            update past it is refused with fmi3Error.
 *   MIMIC 4  an array state (like StateSpace, ME): x is a Float64 array of n = 3 elements (a structural
 *            parameter), der(x) = -x; nx other than 3 is refused ("Expected nx=3").
 *   MIMIC 5  no stepSize, stiff (like Roberts, CS and ME): x' = -1000 (x - 1), x(0) = 0; Co-Simulation
 *            integrates with an internal fixed step of 1e-6 s (a step of 1e6 s would take 1e12 internal
 *            steps); the default experiment has no stepSize and a stop time of 1e8 s.
 *   MIMIC 6  NaN passed through (like Feedthrough, CS): y = u, a NaN input gives a NaN output with fmi3OK.
 *   MIMIC 8  a quiet error (CS): fmi3ExitInitializationMode logs an information message; fmi3DoStep from
 *            t >= 0.5 returns fmi3Error and logs nothing (the checker must not quote the earlier message).
 *   MIMIC 9  an FMU state that is a plain copy of the instance's values (like every Reference-FMU, CS): x' = u,
 *            y = x; fmi3GetFMUState allocates a copy, fmi3SerializeFMUState writes its bytes, deserializing
 *            checks only the size: a NaN written into a state is restored, and a freed state whose address
 *            the next state got is set as that state.
 *   MIMIC 7  the Reference-FMUs' real defects (CS and ME): a step of NaN loops for ever (CS); fmi3SetTime(NaN)
 *            returns fmi3OK (ME); fmi3UpdateDiscreteStates is accepted in Continuous-Time Mode (ME).
 *
 * Apart from that the units are strict: a state machine per the standard, NULL and unknown arguments refused,
 * and instance handles that are never reused (a token: the n-th instance ever made is n * 16), so that the
 * checks they are not about pass. Value references: u 1, d 2, y 3, yd 4, counter 5, n 6, x 7, der(x) 8.
 */
#include <math.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3PlatformTypes.h"
#include "fmi3FunctionTypes.h"

#define EXPORT __attribute__((visibility("default")))
#ifndef MIMIC
#error "MIMIC must be defined"
#endif
#ifndef TOKEN
#error "TOKEN must be defined"
#endif

enum { INST = 1, INIT = 2, STEP = 4, EVENT = 8, CONT = 16, TERM = 32 };
#define NX (MIMIC == 4 ? 3 : (MIMIC == 5 ? 1 : 0))
#define SLOTS 256

typedef struct {
    uintptr_t token;
    fmi3LogMessageCallback log;
    fmi3InstanceEnvironment env;
    bool me;
    int state;
    double time, u, d, x[3], next_tick;
    int counter;
    bool ended;
} Instance;

static Instance *slots[SLOTS];
static uintptr_t made;
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;

static Instance *get(fmi3Instance h) {
    Instance *c = NULL;
    pthread_mutex_lock(&lock);
    for (int i = 0; i < SLOTS; i++)
        if (slots[i] && slots[i]->token == (uintptr_t)h) c = slots[i];
    pthread_mutex_unlock(&lock);
    return c;
}

static void say(Instance *c, fmi3Status s, const char *msg) {
    if (c && c->log) c->log(c->env, s, "logStatusError", msg);
}

static bool in(Instance *c, int mask, const char *fn) {
    if (!c) return false;
    if (c->state & mask) return true;
    say(c, fmi3Error, fn);
    return false;
}

static void reset_values(Instance *c) {
    c->time = 0.0; c->u = 0.0; c->d = 0.0; c->counter = 0; c->next_tick = 0.1; c->ended = false;
    for (int i = 0; i < 3; i++) c->x[i] = (MIMIC == 4) ? 1.0 : 0.0;
}

static fmi3Instance make(fmi3String name, fmi3String token, bool me, fmi3InstanceEnvironment env,
                         fmi3LogMessageCallback log) {
    if (!name || !token || strcmp(token, TOKEN) != 0) return NULL;
    Instance *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->log = log; c->env = env; c->me = me; c->state = INST;
    reset_values(c);
    pthread_mutex_lock(&lock);
    int k = -1;
    for (int i = 0; i < SLOTS && k < 0; i++)
        if (!slots[i]) k = i;
    if (k >= 0) {
        c->token = ++made * 16;
        slots[k] = c;
    }
    pthread_mutex_unlock(&lock);
    if (k < 0) { free(c); return NULL; }
    return (fmi3Instance)c->token;
}

EXPORT fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String res, fmi3Boolean vis,
        fmi3Boolean log_on, fmi3Boolean ev, fmi3Boolean early, const fmi3ValueReference req[], size_t nreq,
        fmi3InstanceEnvironment env, fmi3LogMessageCallback log, fmi3IntermediateUpdateCallback upd) {
    (void)res; (void)vis; (void)log_on; (void)ev; (void)early; (void)req; (void)nreq; (void)upd;
    if (MIMIC == 1 || MIMIC == 4) return NULL;  /* Model Exchange only */
    return make(name, token, false, env, log);
}

EXPORT fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String res, fmi3Boolean vis,
        fmi3Boolean log_on, fmi3InstanceEnvironment env, fmi3LogMessageCallback log) {
    (void)res; (void)vis; (void)log_on;
    if (MIMIC == 6 || MIMIC == 8 || MIMIC == 9) return NULL;  /* Co-Simulation only */
    return make(name, token, true, env, log);
}

EXPORT void fmi3FreeInstance(fmi3Instance h) {
    pthread_mutex_lock(&lock);
    for (int i = 0; i < SLOTS; i++)
        if (slots[i] && slots[i]->token == (uintptr_t)h) { free(slots[i]); slots[i] = NULL; }
    pthread_mutex_unlock(&lock);
}

EXPORT fmi3Status fmi3EnterInitializationMode(fmi3Instance h, fmi3Boolean tol_def, fmi3Float64 tol, fmi3Float64 t0,
                                              fmi3Boolean stop_def, fmi3Float64 t1) {
    (void)tol_def; (void)tol; (void)stop_def; (void)t1;
    Instance *c = get(h);
    if (!in(c, INST, "fmi3EnterInitializationMode: only in Instantiated")) return fmi3Error;
    if (!isfinite(t0)) { say(c, fmi3Error, "the start time must be finite"); return fmi3Error; }
    c->time = t0;
    c->next_tick = t0 + 0.1;
    c->state = INIT;
    return fmi3OK;
}

EXPORT fmi3Status fmi3ExitInitializationMode(fmi3Instance h) {
    Instance *c = get(h);
    if (!in(c, INIT, "fmi3ExitInitializationMode: only in Initialization Mode")) return fmi3Error;
    c->state = c->me ? EVENT : STEP;
    if (MIMIC == 8) say(c, fmi3OK, "initialised");
    return fmi3OK;
}

EXPORT fmi3Status fmi3Terminate(fmi3Instance h) {
    Instance *c = get(h);
    if (!in(c, STEP | EVENT | CONT, "fmi3Terminate: only after initialization")) return fmi3Error;
    c->state = TERM;
    return fmi3OK;
}

EXPORT fmi3Status fmi3Reset(fmi3Instance h) {
    Instance *c = get(h);
    if (!c) return fmi3Error;
    reset_values(c);
    c->state = INST;
    return fmi3OK;
}

static double value(Instance *c, fmi3ValueReference vr, bool *ok) {
    *ok = true;
    switch (vr) {
    case 1: return c->u;
    case 2: return c->d;
    case 3: return (MIMIC == 4 || MIMIC == 5 || MIMIC == 9) ? c->x[0] : c->u;
    case 4: return c->d;
    case 7: return c->x[0];
    default: *ok = false; return 0.0;
    }
}

EXPORT fmi3Status fmi3GetFloat64(fmi3Instance h, const fmi3ValueReference vr[], size_t n, fmi3Float64 v[], size_t nv) {
    Instance *c = get(h);
    if (!in(c, INIT | STEP | EVENT | CONT | TERM, "fmi3GetFloat64: not in Instantiated")) return fmi3Error;
    if ((n && (!vr || !v)) || nv < n) { say(c, fmi3Error, "fmi3GetFloat64: NULL array"); return fmi3Error; }
    for (size_t i = 0; i < n; i++) {
        bool ok;
        if (MIMIC == 4 && vr[i] == 7) {  /* the array x: its elements in a row */
            if (i + 3 > nv) return fmi3Error;
            memcpy(v + i, c->x, sizeof c->x);
            continue;
        }
        v[i] = value(c, vr[i], &ok);
        if (!ok) { say(c, fmi3Error, "fmi3GetFloat64: unknown value reference"); return fmi3Error; }
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetFloat64(fmi3Instance h, const fmi3ValueReference vr[], size_t n, const fmi3Float64 v[],
                                 size_t nv) {
    Instance *c = get(h);
    if (!in(c, INST | INIT | STEP | EVENT | CONT | TERM, "fmi3SetFloat64")) return fmi3Error;
    if ((n && (!vr || !v)) || nv < n) { say(c, fmi3Error, "fmi3SetFloat64: NULL array"); return fmi3Error; }
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 1 && (MIMIC == 1 || MIMIC == 6 || MIMIC == 7 || MIMIC == 8 || MIMIC == 9)) c->u = v[i];
        else if (vr[i] == 2 && MIMIC == 1) {
            if (c->state & CONT) {
                say(c, fmi3Error, "Variable d can only be set after instantiation, in Initialization Mode and in Event Mode.");
                return fmi3Error;
            }
            c->d = v[i];
        } else { say(c, fmi3Error, "fmi3SetFloat64: not an input"); return fmi3Error; }
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3GetInt32(fmi3Instance h, const fmi3ValueReference vr[], size_t n, fmi3Int32 v[], size_t nv) {
    Instance *c = get(h);
    if (!in(c, INIT | STEP | EVENT | CONT | TERM, "fmi3GetInt32: not in Instantiated")) return fmi3Error;
    if ((n && (!vr || !v)) || nv < n) return fmi3Error;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 5 && MIMIC == 2) v[i] = c->counter;
        else if (vr[i] == 6 && MIMIC == 4) v[i] = 3;
        else { say(c, fmi3Error, "fmi3GetInt32: unknown value reference"); return fmi3Error; }
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetInt32(fmi3Instance h, const fmi3ValueReference vr[], size_t n, const fmi3Int32 v[], size_t nv) {
    (void)vr; (void)n; (void)v; (void)nv;
    say(get(h), fmi3Error, "fmi3SetInt32: no Int32 input");
    return fmi3Error;
}

static void derivatives(Instance *c, double dx[]) {
    for (int i = 0; i < NX; i++) dx[i] = (MIMIC == 5) ? -1000.0 * (c->x[i] - 1.0) : -c->x[i];
}

EXPORT fmi3Status fmi3DoStep(fmi3Instance h, fmi3Float64 t, fmi3Float64 dt, fmi3Boolean nsp, fmi3Boolean *event,
                             fmi3Boolean *term, fmi3Boolean *early, fmi3Float64 *last) {
    (void)nsp;
    Instance *c = get(h);
    if (!in(c, STEP, "fmi3DoStep: only in Step Mode")) return fmi3Error;
    if (!event || !term || !early || !last) return fmi3Error;
    *event = false; *term = false; *early = false; *last = t;
#if MIMIC == 7
    if (isnan(dt)) { volatile unsigned long spin = 0; for (;;) spin++; }
#endif
    if (!(dt > 0.0) || !isfinite(dt) || !isfinite(t)) { say(c, fmi3Error, "bad step"); return fmi3Error; }
    if (c->ended) { say(c, fmi3Error, "the simulation has ended"); return fmi3Error; }
    if (MIMIC == 8 && t >= 0.5 - 1e-9) return fmi3Error;
    double t1 = t + dt;
#if MIMIC == 5
    double hs = 1e-6;
    double x = c->x[0];
    for (double tk = t; tk < t1; tk += hs) x += hs * (-1000.0 * (x - 1.0));
    c->x[0] = x;
#elif MIMIC == 9
    c->x[0] += c->u * dt;
#elif MIMIC == 2
    while (c->next_tick <= t1 + 1e-9 && !c->ended) {
        c->counter++;
        c->next_tick += 0.1;
        if (c->counter >= 5) c->ended = true;
    }
    *term = c->ended;
#endif
    c->time = t1;
    *last = t1;
    return fmi3OK;
}

EXPORT fmi3Status fmi3EnterEventMode(fmi3Instance h) {
    Instance *c = get(h);
    if (!in(c, CONT, "fmi3EnterEventMode: only in Continuous-Time Mode")) return fmi3Error;
    c->state = EVENT;
    return fmi3OK;
}

EXPORT fmi3Status fmi3UpdateDiscreteStates(fmi3Instance h, fmi3Boolean *need, fmi3Boolean *term, fmi3Boolean *nom,
                                           fmi3Boolean *val, fmi3Boolean *def, fmi3Float64 *next) {
    Instance *c = get(h);
    int mask = (MIMIC == 7) ? (EVENT | CONT) : EVENT;
    if (!in(c, mask, "fmi3UpdateDiscreteStates: only in Event Mode")) return fmi3Error;
    if (!need || !term || !nom || !val || !def || !next) return fmi3Error;
    *need = false; *nom = false; *val = false; *def = false; *next = 0.0; *term = false;
    if (MIMIC == 2) {
        if (c->ended) { say(c, fmi3Error, "Variable counter cannot be incremented past 5."); return fmi3Error; }
        if (c->time >= c->next_tick - 1e-9) {
            c->counter++;
            c->next_tick += 0.1;
        }
        c->ended = c->counter >= 5;
        *term = c->ended;
        *def = !c->ended;
        *next = c->next_tick;
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance h) {
    Instance *c = get(h);
    if (!in(c, EVENT, "fmi3EnterContinuousTimeMode: only in Event Mode")) return fmi3Error;
    c->state = CONT;
    return fmi3OK;
}

EXPORT fmi3Status fmi3CompletedIntegratorStep(fmi3Instance h, fmi3Boolean nsp, fmi3Boolean *enter, fmi3Boolean *term) {
    (void)nsp;
    Instance *c = get(h);
    if (!in(c, CONT, "fmi3CompletedIntegratorStep: only in Continuous-Time Mode")) return fmi3Error;
    if (!enter || !term) return fmi3Error;
    *enter = false; *term = false;
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetTime(fmi3Instance h, fmi3Float64 t) {
    Instance *c = get(h);
    if (!in(c, EVENT | CONT, "fmi3SetTime: only in Event or Continuous-Time Mode")) return fmi3Error;
    if (MIMIC != 7 && !isfinite(t)) { say(c, fmi3Error, "fmi3SetTime: the time must be finite"); return fmi3Error; }
    c->time = t;
    return fmi3OK;
}

static fmi3Status states_call(Instance *c, size_t n, const char *fn) {
    if (!in(c, INIT | EVENT | CONT | TERM, fn)) return fmi3Error;
    if (n != NX) {
        say(c, fmi3Error, MIMIC == 4 ? "Expected nx=3." : "wrong number of continuous states");
        return fmi3Error;
    }
    return fmi3OK;
}

EXPORT fmi3Status fmi3GetContinuousStates(fmi3Instance h, fmi3Float64 x[], size_t n) {
    Instance *c = get(h);
    if (states_call(c, n, "fmi3GetContinuousStates") != fmi3OK || (n && !x)) return fmi3Error;
    memcpy(x, c->x, n * sizeof(double));
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetContinuousStates(fmi3Instance h, const fmi3Float64 x[], size_t n) {
    Instance *c = get(h);
    if (c && !(c->state & CONT)) { say(c, fmi3Error, "fmi3SetContinuousStates: only in Continuous-Time Mode"); return fmi3Error; }
    if (states_call(c, n, "fmi3SetContinuousStates") != fmi3OK || (n && !x)) return fmi3Error;
    memcpy(c->x, x, n * sizeof(double));
    return fmi3OK;
}

EXPORT fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance h, fmi3Float64 dx[], size_t n) {
    Instance *c = get(h);
    if (c && c->state == TERM) return fmi3Error;
    if (states_call(c, n, "fmi3GetContinuousStateDerivatives") != fmi3OK || (n && !dx)) return fmi3Error;
    derivatives(c, dx);
    return fmi3OK;
}

#if MIMIC == 9
typedef struct {
    int state;
    double time, u, d, x[3], next_tick;
    int counter;
    bool ended;
} Snap;

static void to_snap(const Instance *c, Snap *p) {
    p->state = c->state; p->time = c->time; p->u = c->u; p->d = c->d; memcpy(p->x, c->x, sizeof p->x);
    p->next_tick = c->next_tick; p->counter = c->counter; p->ended = c->ended;
}

EXPORT fmi3Status fmi3GetFMUState(fmi3Instance h, fmi3FMUState *s) {
    Instance *c = get(h);
    if (!c || !s) return fmi3Error;
    Snap *p = *s ? (Snap *)*s : malloc(sizeof(Snap));
    if (!p) return fmi3Error;
    to_snap(c, p);
    *s = p;
    return fmi3OK;
}

EXPORT fmi3Status fmi3SetFMUState(fmi3Instance h, fmi3FMUState s) {
    Instance *c = get(h);
    if (!c || !s) { say(c, fmi3Error, "fmi3SetFMUState: NULL state"); return fmi3Error; }
    const Snap *p = s;
    c->state = p->state; c->time = p->time; c->u = p->u; c->d = p->d; memcpy(c->x, p->x, sizeof c->x);
    c->next_tick = p->next_tick; c->counter = p->counter; c->ended = p->ended;
    return fmi3OK;
}

EXPORT fmi3Status fmi3FreeFMUState(fmi3Instance h, fmi3FMUState *s) {
    if (!get(h) || !s) return fmi3Error;
    free(*s);
    *s = NULL;
    return fmi3OK;
}

EXPORT fmi3Status fmi3SerializedFMUStateSize(fmi3Instance h, fmi3FMUState s, size_t *size) {
    if (!get(h) || !s || !size) return fmi3Error;
    *size = sizeof(Snap);
    return fmi3OK;
}

EXPORT fmi3Status fmi3SerializeFMUState(fmi3Instance h, fmi3FMUState s, fmi3Byte buf[], size_t size) {
    if (!get(h) || !s || !buf || size < sizeof(Snap)) return fmi3Error;
    memcpy(buf, s, sizeof(Snap));
    return fmi3OK;
}

EXPORT fmi3Status fmi3DeserializeFMUState(fmi3Instance h, const fmi3Byte buf[], size_t size, fmi3FMUState *s) {
    if (!get(h) || !buf || !s || size != sizeof(Snap)) return fmi3Error;
    Snap *p = malloc(sizeof(Snap));
    if (!p) return fmi3Error;
    memcpy(p, buf, sizeof(Snap));
    *s = p;
    return fmi3OK;
}
#endif
