/* A hostile FMI master in C, for both FMI versions: loads an FMU binary with dlopen and drives it the way
 * a careless or malicious tool would. Each mode prints one summary line "ok ..." and exits 0, or prints
 * what went wrong (and the FMU's last log message) and exits 1. Run under valgrind / a timeout by
 * tests/test_hardening.py. The version switch: without `-3` the FMI 2.0 modes (fmi2* functions, LIB's
 * GUID), with `-3` first the FMI 3.0 modes (fmi3* functions, LIB's instantiation token).
 *
 * FMI 2.0 Co-Simulation:
 *   fmi_hostile LIB GUID cycles N        instantiate/init/step/state/serialize/free N times
 *   fmi_hostile LIB GUID reload N        dlopen + one instance + dlclose, N times
 *   fmi_hostile LIB GUID threads T N     T threads, N cycles each (with state reuse), results compared
 *   fmi_hostile LIB GUID hang            calls that used to run forever must return an error promptly
 *   fmi_hostile LIB GUID fuzz N SEED     serialized states with random bytes and a valid CRC
 *   fmi_hostile LIB GUID extreme         extreme parameters: errors, never infinite values with fmi2OK
 *   fmi_hostile LIB GUID reuse N [T [H]] T threads (default 1), N rounds each: an instance and its FMU states
 *                                        freed, a new instance (and state) that usually gets their memory; every
 *                                        stale instance and state handle kept (the first, the last ones, other
 *                                        threads') refused with fmi2Error, the new instance untouched; with H,
 *                                        H more instances live all the while (unchanged at the end)
 *   fmi_hostile LIB GUID cross LIB2 N    LIB2 a copy of LIB under another name (a second loaded library): N rounds
 *                                        of an instance and state in each, each library's handles refused by the other
 *   fmi_hostile LIB GUID race N          deliberate misuse: two threads call ONE instance at the same time
 *                                        (FMI forbids it); under ThreadSanitizer this must be reported, which
 *                                        shows the detector is live (results are not checked)
 *
 * Model Exchange (fmuType fmi2ModelExchange = 0), every ME entry point:
 *   fmi_hostile LIB GUID me N_EVENTS N_FUZZ   bad calls (NULL component and pointers, wrong lengths, wrong
 *                                        state, NaN/Inf states and time, time before the last event), very many
 *                                        event iterations, FMU states in event and continuous-time mode
 *                                        (corrupted ones too), each with the prescribed status and a logger
 *                                        message naming the function; then a legitimate explicit-Euler run
 *                                        checked against the closed form (w_z = tau/I_z t, |q| = 1 within 1e-6)
 *   fmi_hostile LIB GUID me-reload N     dlopen + an ME instance (Euler steps, states) alive while a CS cycle
 *                                        runs + dlclose, N times
 *   fmi_hostile LAWLIB LAWGUID me-law N  a static law (PdController, 0 states) as ME: the same bad calls, a run
 *                                        whose outputs equal a Co-Simulation instance's bit for bit
 *
 * FMI 3.0 (Co-Simulation and Model Exchange):
 *   fmi_hostile -3 LIB TOKEN cycles N    instantiate/init/step/state/serialize/deserialize/free N times:
 *                                        every cycle gives the same bits
 *   fmi_hostile -3 LIB TOKEN abuse       NULL and foreign pointers, wrong states, NaN, bool bytes other than
 *                                        0/1, wrong counts, every refused function: the prescribed status,
 *                                        a log message naming the function, and the instance recovers
 *   fmi_hostile -3 LIB TOKEN mixed       an FMI 2.0 and an FMI 3.0 instance of the same library side by side
 *                                        give identical results; neither API accepts the other's instance
 *   fmi_hostile -3 LIB TOKEN reuse N [T [H]] the reuse mode with the FMI 3.0 functions (fmi3Error)
 *   fmi_hostile -3 LIB TOKEN me          Model Exchange: NULL and foreign pointers on every ME entry point,
 *                                        wrong call order, wrong lengths, NaN states and times, Co-Simulation
 *                                        calls on an ME instance and FMU states across the two; then an
 *                                        explicit Euler run whose rate matches the closed form w_x = tau t / I_xx
 *
 * LIB must be an AttitudePlant binary (value references from modelDescription/AttitudePlant.xml and
 * modelDescription/fmi3/AttitudePlant.xml); LAWLIB a PdController binary (modelDescription/PdController.xml).
 * The FMI 3.0 section (after the FMI 2.0 one) keeps its own global function table; its names that would
 * clash with the FMI 2.0 section carry a 3 (load3, ready3, sym3, lib3, serialize3, cycle3, step3).
 */
#include <dlfcn.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/time.h>
#include <unistd.h>

typedef void *C;
typedef int St;
enum { OK = 0, WARNING = 1, DISCARD = 2, ERROR = 3, FATAL = 4 };
typedef struct {
    void (*logger)(void *, const char *, int, const char *, const char *, ...);
    void *(*alloc)(size_t, size_t);
    void (*free)(void *);
    void (*step_finished)(void *, int);
    void *env;
} Callbacks;

typedef struct {
    void *lib;
    C (*instantiate)(const char *, int, const char *, const char *, const Callbacks *, int, int);
    void (*free_instance)(C);
    St (*setup)(C, int, double, double, int, double);
    St (*enter_init)(C);
    St (*exit_init)(C);
    St (*set_real)(C, const unsigned *, size_t, const double *);
    St (*get_real)(C, const unsigned *, size_t, double *);
    St (*set_integer)(C, const unsigned *, size_t, const int *);
    St (*do_step)(C, double, double, int);
    St (*get_state)(C, void **);
    St (*set_state)(C, void *);
    St (*free_state)(C, void **);
    St (*ser_size)(C, void *, size_t *);
    St (*serialize)(C, void *, char *, size_t);
    St (*deserialize)(C, const char *, size_t, void **);
    St (*terminate)(C);
    St (*reset)(C);
    /* Model Exchange */
    St (*enter_event_mode)(C);
    St (*new_discrete_states)(C, void *);
    St (*enter_ct_mode)(C);
    St (*completed_step)(C, int, int *, int *);
    St (*set_time)(C, double);
    St (*set_states)(C, const double *, size_t);
    St (*get_derivatives)(C, double *, size_t);
    St (*get_indicators)(C, double *, size_t);
    St (*get_states)(C, double *, size_t);
    St (*get_nominals)(C, double *, size_t);
} Fmi;

/* fmi2EventInfo */
typedef struct {
    int new_discrete_states_needed;
    int terminate_simulation;
    int nominals_changed;
    int values_changed;
    int next_event_time_defined;
    double next_event_time;
} EventInfo;

#if defined(__SANITIZE_THREAD__)
/* A Rust library built with -Zsanitizer=thread calls __tsan_memcpy/__tsan_memmove/__tsan_memset, which
 * LLVM's TSan runtime has and GCC 12's libtsan does not. Here they forward to the C functions, which
 * libtsan intercepts (so the accesses are still checked); build with -rdynamic so that the dlopen'ed
 * library finds them. */
void *__tsan_memcpy(void *d, const void *s, size_t n) { return memcpy(d, s, n); }
void *__tsan_memmove(void *d, const void *s, size_t n) { return memmove(d, s, n); }
void *__tsan_memset(void *d, int c, size_t n) { return memset(d, c, n); }
#endif

/* AttitudePlant value references */
enum { VR_TORQUE_CMD_X = 0, VR_Q_W = 10, VR_W_X = 14, VR_MAX_STEP = 130, VR_INTEGRATOR = 140, VR_ACTUATOR_MODE = 142,
       VR_WHEEL_COEFF = 153, VR_WHEEL_CURRENT = 154, VR_ORBIT_RADIUS = 161, VR_INIT_W_X = 113, VR_NOISE_STD_X = 180 };

static const char *LIB, *GUID;
static int quiet_logger_count;
/* the last message the FMU logged on this thread (formatted: the FMU escapes '%' as "%%") */
static __thread char last_msg[4096];
static __thread int last_status = -1;

static void logger(void *env, const char *name, int status, const char *cat, const char *msg, ...) {
    (void)env; (void)name; (void)cat;
    va_list ap;
    va_start(ap, msg);
    vsnprintf(last_msg, sizeof last_msg, msg, ap);
    va_end(ap);
    last_status = status;
    if (getenv("HOSTILE_VERBOSE")) fprintf(stderr, "[%d] %s\n", status, last_msg);
    __atomic_add_fetch(&quiet_logger_count, 1, __ATOMIC_RELAXED);
}
static const Callbacks CB = {logger, calloc, free, NULL, NULL};

static void die(const char *what) { printf("FAIL %s (last message: %s)\n", what, last_msg); fflush(stdout); exit(1); }
#define CHECK(cond, what) do { if (!(cond)) die(what); } while (0)

static void *sym(void *lib, const char *name) {
    void *p = dlsym(lib, name);
    if (!p) { printf("FAIL missing symbol %s\n", name); exit(1); }
    return p;
}

static Fmi load(void) {
    Fmi f;
    f.lib = dlopen(LIB, RTLD_NOW | RTLD_LOCAL);
    if (!f.lib) { printf("FAIL dlopen %s: %s\n", LIB, dlerror()); exit(1); }
    f.instantiate = sym(f.lib, "fmi2Instantiate");
    f.free_instance = sym(f.lib, "fmi2FreeInstance");
    f.setup = sym(f.lib, "fmi2SetupExperiment");
    f.enter_init = sym(f.lib, "fmi2EnterInitializationMode");
    f.exit_init = sym(f.lib, "fmi2ExitInitializationMode");
    f.set_real = sym(f.lib, "fmi2SetReal");
    f.get_real = sym(f.lib, "fmi2GetReal");
    f.set_integer = sym(f.lib, "fmi2SetInteger");
    f.do_step = sym(f.lib, "fmi2DoStep");
    f.get_state = sym(f.lib, "fmi2GetFMUstate");
    f.set_state = sym(f.lib, "fmi2SetFMUstate");
    f.free_state = sym(f.lib, "fmi2FreeFMUstate");
    f.ser_size = sym(f.lib, "fmi2SerializedFMUstateSize");
    f.serialize = sym(f.lib, "fmi2SerializeFMUstate");
    f.deserialize = sym(f.lib, "fmi2DeSerializeFMUstate");
    f.terminate = sym(f.lib, "fmi2Terminate");
    f.reset = sym(f.lib, "fmi2Reset");
    f.enter_event_mode = sym(f.lib, "fmi2EnterEventMode");
    f.new_discrete_states = sym(f.lib, "fmi2NewDiscreteStates");
    f.enter_ct_mode = sym(f.lib, "fmi2EnterContinuousTimeMode");
    f.completed_step = sym(f.lib, "fmi2CompletedIntegratorStep");
    f.set_time = sym(f.lib, "fmi2SetTime");
    f.set_states = sym(f.lib, "fmi2SetContinuousStates");
    f.get_derivatives = sym(f.lib, "fmi2GetDerivatives");
    f.get_indicators = sym(f.lib, "fmi2GetEventIndicators");
    f.get_states = sym(f.lib, "fmi2GetContinuousStates");
    f.get_nominals = sym(f.lib, "fmi2GetNominalsOfContinuousStates");
    return f;
}

static C ready(const Fmi *f, int noise) {
    C c = f->instantiate("hostile", 1, GUID, NULL, &CB, 0, 0);
    CHECK(c, "instantiate");
    CHECK(f->setup(c, 0, 0.0, 0.0, 0, 0.0) == OK, "setup");
    CHECK(f->enter_init(c) == OK, "enter init");
    unsigned vr[2] = {VR_INIT_W_X, VR_NOISE_STD_X};
    double v[2] = {0.05, noise ? 0.5 : 0.0};
    CHECK(f->set_real(c, vr, 2, v) == OK, "set parameters");
    CHECK(f->exit_init(c) == OK, "exit init");
    return c;
}

static void step_n(const Fmi *f, C c, double *t, int n) {
    unsigned vr = VR_TORQUE_CMD_X;
    for (int k = 0; k < n; k++) {
        double u = 3.0 * sin(*t);
        CHECK(f->set_real(c, &vr, 1, &u) == OK, "set input");
        CHECK(f->do_step(c, *t, 0.01, 1) == OK, "doStep");
        *t += 0.01;
    }
}

static double read_wx(const Fmi *f, C c) {
    unsigned vr = VR_W_X;
    double w = NAN;
    CHECK(f->get_real(c, &vr, 1, &w) == OK, "get output");
    return w;
}

static char *serialize(const Fmi *f, C c, void *s, size_t *n) {
    CHECK(f->ser_size(c, s, n) == OK, "serialized size");
    char *b = malloc(*n);
    CHECK(f->serialize(c, s, b, *n) == OK, "serialize");
    return b;
}

/* one full cycle: returns w_x at t = 0.15 s. Both variants restore a state and continue to the same
   end time, so they must agree bit for bit with each other and with an uninterrupted run. */
static double cycle(const Fmi *f, int reuse) {
    C c = ready(f, 1);
    double t = 0.0;
    step_n(f, c, &t, 5);
    double t_saved = t;
    void *s = NULL;
    CHECK(f->get_state(c, &s) == OK, "get state");
    step_n(f, c, &t, 5);
    if (reuse) {
        CHECK(f->get_state(c, &s) == OK, "get state (reuse)");
        t_saved = t;
    }
    size_t n;
    char *b = serialize(f, c, s, &n);
    void *s2 = NULL;
    CHECK(f->deserialize(c, b, n, &s2) == OK, "deserialize");
    if (reuse) CHECK(f->deserialize(c, b, n, &s) == OK, "deserialize (reuse)");
    CHECK(f->set_state(c, s2) == OK, "set state");
    t = t_saved;
    step_n(f, c, &t, reuse ? 5 : 10);
    double w = read_wx(f, c);
    free(b);
    CHECK(f->free_state(c, &s2) == OK, "free state");
    /* s is freed with the instance */
    f->free_instance(c);
    return w;
}

/* ----- CRC-32 (IEEE), as used by the state format ----- */
static uint32_t crc32(const unsigned char *p, size_t n) {
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return ~c;
}
static void fix_crc(unsigned char *b, size_t n) {
    uint32_t crc = crc32(b, n - 4);
    memcpy(b + n - 4, &crc, 4); /* little endian host */
}

static uint64_t rng;
static uint64_t next(void) { rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17; return rng; }

/* a restored state must either be refused or give a usable instance (step returns, finite outputs) */
static int try_state(const Fmi *f, C c, unsigned char *b, size_t n, int *accepted) {
    void *s = NULL;
    St st = f->deserialize(c, (const char *)b, n, &s);
    if (st != OK) { CHECK(st == ERROR, "deserialize returned neither OK nor Error"); return 0; }
    (*accepted)++;
    CHECK(f->set_state(c, s) == OK, "set accepted state");
    double t = 0.0;
    unsigned vr = VR_W_X; double w;
    /* the restored time may be anything finite: read it back through a step at that time is not possible
       without fmi2GetRealStatus; stepping from a wrong time is refused, which is fine */
    St g = f->get_real(c, &vr, 1, &w);
    CHECK(g == OK || g == ERROR, "get after restore");
    if (g == OK) CHECK(isfinite(w), "fmi2OK with a non-finite output");
    (void)t;
    f->free_state(c, &s);
    return 1;
}

/* race mode: two threads on one instance (forbidden by FMI), to check that ThreadSanitizer reports it */
typedef struct { const Fmi *f; C c; int n; int writer; } Racer;
static void *racer(void *arg) {
    Racer *r = (Racer *)arg;
    unsigned in = VR_TORQUE_CMD_X, out = VR_W_X;
    for (int i = 0; i < r->n; i++) {
        double v = 1e-3 * i;
        if (r->writer) r->f->set_real(r->c, &in, 1, &v); else r->f->get_real(r->c, &out, 1, &v);
    }
    return NULL;
}

/* threads mode: each thread runs its own instances (with state reuse) and compares with the reference */
typedef struct { const Fmi *f; int n; double ref; int bad; } Work;
static void *worker(void *arg) {
    Work *w = (Work *)arg;
    for (int i = 0; i < w->n; i++)
        if (cycle(w->f, i % 2) != w->ref) w->bad = 1;
    return NULL;
}

/* ===================================================================================================
 * Model Exchange (fmuType fmi2ModelExchange = 0)
 * =================================================================================================== */

/* more AttitudePlant value references; continuous states and their derivatives (docs/model_exchange.md) */
enum { NX = 18, VR_TORQUE_CMD_Z = 2, VR_Q_X = 11, VR_Q_Y = 12, VR_Q_Z = 13, VR_W_Z = 16, VR_INERTIA_ZZ = 102,
       VR_FAULT_TIME = 126, VR_NOISE_HOLD = 183 };
#define VR_STATE(k) (1000000000u + (unsigned)(k))
#define VR_DER(k) (1000100000u + (unsigned)(k))
enum { X_QW = 0, X_QX = 1, X_QY = 2, X_QZ = 3, X_WX = 9, X_WY = 10, X_WZ = 11 };

static int n_checked; /* refused calls whose status and message were checked */

/* The call must return `want`. A refused call on an instance must have logged, with that status, a message
   naming `fn` and containing `reason` (when given); fn NULL: no message at all (no instance to log to). */
static void expect_at(St got, St want, const char *fn, const char *reason, const char *call, int line) {
    if (got != want) {
        printf("FAIL line %d: %s returned %d, expected %d (last message: \"%s\")\n", line, call, got, want, last_msg);
        fflush(stdout);
        exit(1);
    }
    if (want == OK) return;
    if (!fn) {
        if (last_msg[0]) {
            printf("FAIL line %d: %s logged \"%s\" without an instance\n", line, call, last_msg);
            fflush(stdout);
            exit(1);
        }
    } else if (!strstr(last_msg, fn) || (reason && !strstr(last_msg, reason)) || last_status != want) {
        printf("FAIL line %d: %s: message \"%s\" (status %d) must name %s and say \"%s\"\n", line, call, last_msg,
               last_status, fn, reason ? reason : "");
        fflush(stdout);
        exit(1);
    }
    n_checked++;
}
#define EXPECT(call, want, fn, reason)                                  \
    do {                                                                \
        last_msg[0] = 0;                                                \
        last_status = -1;                                               \
        St st_ = (call);                                                \
        expect_at(st_, want, fn, reason, #call, __LINE__);              \
    } while (0)
#define OKAY(call) EXPECT(call, OK, NULL, NULL)
#define REFUSED(call, fn, reason) EXPECT(call, ERROR, fn, reason)

static C instance_of_type(const Fmi *f, const char *name, int type) {
    C c = f->instantiate(name, type, GUID, NULL, &CB, 0, 0);
    CHECK(c, "fmi2Instantiate");
    return c;
}

/* setup, initialization with the given parameters, exit: event mode (ME) */
static void init_with(const Fmi *f, C c, const unsigned *vr, const double *v, size_t n) {
    OKAY(f->setup(c, 0, 0.0, 0.0, 0, 0.0));
    OKAY(f->enter_init(c));
    if (n) OKAY(f->set_real(c, vr, n, v));
    OKAY(f->exit_init(c));
}

/* The event iteration (event mode): returns whether the states changed; *tnext = next time event or INFINITY. */
static int event_iteration(const Fmi *f, C c, double *tnext) {
    EventInfo ei;
    int changed = 0, k = 0;
    do {
        memset(&ei, 0x5A, sizeof ei);
        OKAY(f->new_discrete_states(c, &ei));
        CHECK(ei.terminate_simulation == 0 && ei.nominals_changed == 0, "terminateSimulation or nominalsChanged");
        CHECK(ei.new_discrete_states_needed == 0 || ei.new_discrete_states_needed == 1, "newDiscreteStatesNeeded not a Boolean");
        CHECK(ei.next_event_time_defined == 0 || isfinite(ei.next_event_time), "non-finite next event time");
        changed |= ei.values_changed;
        CHECK(++k < 1000, "event iteration does not end");
    } while (ei.new_discrete_states_needed);
    *tnext = ei.next_event_time_defined ? ei.next_event_time : INFINITY;
    return changed;
}

static double qnorm(const double *x) { return sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3]); }

/* Every ME entry point with a NULL, a foreign and a freed component: fmi2Error, nothing logged. */
static void me_bad_components(const Fmi *f) {
    double x[NX] = {0};
    int a = 0, b = 0;
    EventInfo ei;
    C freed = instance_of_type(f, "freed", 0);
    f->free_instance(freed);
    C bad[3] = {NULL, (C)x, freed};
    for (int i = 0; i < 3; i++) {
        C c = bad[i];
        EXPECT(f->enter_event_mode(c), ERROR, NULL, NULL);
        EXPECT(f->new_discrete_states(c, &ei), ERROR, NULL, NULL);
        EXPECT(f->enter_ct_mode(c), ERROR, NULL, NULL);
        EXPECT(f->completed_step(c, 1, &a, &b), ERROR, NULL, NULL);
        EXPECT(f->set_time(c, 1.0), ERROR, NULL, NULL);
        EXPECT(f->set_states(c, x, NX), ERROR, NULL, NULL);
        EXPECT(f->get_derivatives(c, x, NX), ERROR, NULL, NULL);
        EXPECT(f->get_indicators(c, x, 0), ERROR, NULL, NULL);
        EXPECT(f->get_states(c, x, NX), ERROR, NULL, NULL);
        EXPECT(f->get_nominals(c, x, NX), ERROR, NULL, NULL);
    }
    /* an ME instance of a model: freeing NULL or a freed instance again is a no-op */
    f->free_instance(NULL);
    f->free_instance(freed);
}

/* The calls of the FMI 2.0 ME state table that are not allowed in `state` (nx states): each refused with a
   message naming the function and the state. `allowed_get`: GetContinuousStates/EventIndicators allowed. */
static void me_wrong_state(const Fmi *f, C c, int nx, const char *state) {
    double x[NX] = {1.0};
    int a = 0, b = 0;
    EventInfo ei;
    int ev = !strcmp(state, "EventMode"), ct = !strcmp(state, "ContinuousTimeMode");
    int inst = !strcmp(state, "Instantiated"), init = !strcmp(state, "InitializationMode");
    if (!ev && !ct) {
        REFUSED(f->enter_event_mode(c), "fmi2EnterEventMode", state);
        REFUSED(f->set_time(c, 0.0), "fmi2SetTime", state);
    }
    if (!ev) {
        REFUSED(f->new_discrete_states(c, &ei), "fmi2NewDiscreteStates", state);
        REFUSED(f->enter_ct_mode(c), "fmi2EnterContinuousTimeMode", state);
    }
    if (!ct) {
        REFUSED(f->set_states(c, x, nx), "fmi2SetContinuousStates", state);
        REFUSED(f->completed_step(c, 1, &a, &b), "fmi2CompletedIntegratorStep", state);
    }
    if (inst) {
        REFUSED(f->get_states(c, x, nx), "fmi2GetContinuousStates", state);
        REFUSED(f->get_indicators(c, x, 0), "fmi2GetEventIndicators", state);
    }
    if (inst || init) REFUSED(f->get_derivatives(c, x, nx), "fmi2GetDerivatives", state);
    if (init) REFUSED(f->get_nominals(c, x, nx), "fmi2GetNominalsOfContinuousStates", state);
    /* fmi2DoStep is no Model Exchange call: refused in every state of an ME instance */
    REFUSED(f->do_step(c, 0.0, 0.1, 1), "fmi2DoStep", state);
}

/* NULL arrays and pointers, wrong lengths on an instance in continuous-time mode with nx states */
static void me_bad_pointers(const Fmi *f, C c, int nx) {
    double x[NX + 2] = {0};
    int a = 0, b = 0;
    int wrong[3] = {nx + 1, nx == 0 ? 2 : nx - 1, nx == 0 ? 3 : 0};
    REFUSED(f->completed_step(c, 1, NULL, &b), "fmi2CompletedIntegratorStep", "enterEventMode is NULL");
    REFUSED(f->completed_step(c, 1, &a, NULL), "fmi2CompletedIntegratorStep", "terminateSimulation is NULL");
    for (int i = 0; i < 3; i++) {
        if (wrong[i] == 0 && nx == 0) continue;
        char want[64];
        snprintf(want, sizeof want, "has %d elements", wrong[i]);
        REFUSED(f->set_states(c, x, (size_t)wrong[i]), "fmi2SetContinuousStates", want);
        REFUSED(f->get_derivatives(c, x, (size_t)wrong[i]), "fmi2GetDerivatives", want);
        REFUSED(f->get_states(c, x, (size_t)wrong[i]), "fmi2GetContinuousStates", want);
        REFUSED(f->get_nominals(c, x, (size_t)wrong[i]), "fmi2GetNominalsOfContinuousStates", want);
    }
    if (nx > 0) {
        REFUSED(f->set_states(c, NULL, (size_t)nx), "fmi2SetContinuousStates", "x[] is NULL");
        REFUSED(f->get_derivatives(c, NULL, (size_t)nx), "fmi2GetDerivatives", "derivatives[] is NULL");
        REFUSED(f->get_states(c, NULL, (size_t)nx), "fmi2GetContinuousStates", "x[] is NULL");
        REFUSED(f->get_nominals(c, NULL, (size_t)nx), "fmi2GetNominalsOfContinuousStates", "x_nominal[] is NULL");
        REFUSED(f->set_states(c, x, (size_t)-1), "fmi2SetContinuousStates", "impossible");
        REFUSED(f->get_derivatives(c, x, (size_t)-1 / 8), "fmi2GetDerivatives", "impossible");
    } else { /* 0 states: NULL with length 0 is fine */
        OKAY(f->set_states(c, NULL, 0));
        OKAY(f->get_derivatives(c, NULL, 0));
        OKAY(f->get_states(c, NULL, 0));
        OKAY(f->get_nominals(c, NULL, 0));
    }
    /* no event indicators */
    OKAY(f->get_indicators(c, NULL, 0));
    REFUSED(f->get_indicators(c, x, 1), "fmi2GetEventIndicators", "numberOfEventIndicators = 0");
    REFUSED(f->get_indicators(c, NULL, 2), "fmi2GetEventIndicators", "is NULL");
}

/* one explicit-Euler step from (t, x) with derivatives dx to t1 (continuous-time mode), then the
   completed step; the time event at *tnext and a requested event are handled. Returns 1 on an event. */
static int euler_step(const Fmi *f, C c, int nx, double *x, const double *dx, double t, double t1, double *tnext) {
    int enter = -1, term = -1;
    for (int i = 0; i < nx; i++) x[i] += (t1 - t) * dx[i];
    OKAY(f->set_time(c, t1));
    OKAY(f->set_states(c, x, (size_t)nx));
    OKAY(f->completed_step(c, 1, &enter, &term));
    CHECK((enter == 0 || enter == 1) && term == 0, "completedIntegratorStep flags");
    if (!enter && t1 < *tnext) return 0;
    OKAY(f->enter_event_mode(c));
    if (event_iteration(f, c, tnext)) OKAY(f->get_states(c, x, (size_t)nx));
    OKAY(f->enter_ct_mode(c));
    return 1;
}

/* The legitimate run: AttitudePlant from rest under a constant torque_cmd_z, explicit Euler with step h to
   t_end, a time event (fault_time, no fault effects) on the way. w_z = tau/I_z t exactly (its derivative
   is constant: Euler is exact), w_x = w_y = q_x = q_y = 0, q_z = sin(tau/I_z t^2/4) to the Euler error,
   |q| = 1 within 1e-6 (projection at events). Returns the number of events. */
static int me_euler_run(const Fmi *f, double h, double t_end, int *projections) {
    const double tau = 7.0, iz = 700.0, t_fault = 1.2345;
    C c = instance_of_type(f, "euler", 0);
    unsigned vr[2] = {VR_TORQUE_CMD_Z, VR_FAULT_TIME};
    double v[2] = {tau, t_fault};
    init_with(f, c, vr, v, 2);
    double tnext, x[NX], dx[NX], t = 0.0;
    event_iteration(f, c, &tnext);
    CHECK(tnext == t_fault, "the fault time is the first time event");
    OKAY(f->enter_ct_mode(c));
    OKAY(f->get_states(c, x, NX));
    CHECK(x[X_QW] == 1.0 && x[X_WZ] == 0.0, "initial state at rest");
    double nom[NX];
    OKAY(f->get_nominals(c, nom, NX));
    for (int i = 0; i < NX; i++) CHECK(nom[i] == 1.0, "nominal 1.0");
    int events = 0, time_events = 0;
    *projections = 0;
    while (t < t_end - 1e-12) {
        OKAY(f->get_derivatives(c, dx, NX));
        CHECK(fabs(dx[X_WZ] - tau / iz) <= 1e-15, "der(w_z) = tau/I_z");
        double t1 = fmin(t + h, t_end);
        int at_time_event = t1 >= tnext - 1e-12;
        if (at_time_event) t1 = tnext;
        int ev = euler_step(f, c, NX, x, dx, t, t1, &tnext);
        events += ev;
        time_events += at_time_event;
        if (ev && !at_time_event) {
            (*projections)++;
            CHECK(fabs(qnorm(x) - 1.0) < 1e-14, "projection renormalises q");
        }
        t = t1;
        CHECK(fabs(x[X_WZ] - tau / iz * t) <= 1e-12 * fmax(1.0, t), "w_z = tau/I_z t");
        CHECK(x[X_WX] == 0.0 && x[X_WY] == 0.0 && x[X_QX] == 0.0 && x[X_QY] == 0.0, "rotation about z only");
        CHECK(fabs(qnorm(x) - 1.0) <= 1e-6, "|q| within 1e-6 of 1");
        double th = 0.5 * tau / iz * t * t;
        CHECK(fabs(x[X_QZ] - sin(th / 2)) <= 1e-4 && fabs(x[X_QW] - cos(th / 2)) <= 1e-4, "q follows the closed form");
    }
    CHECK(time_events == 1, "the fault time event was met once");
    /* outputs agree with the states */
    unsigned ov[5] = {VR_W_Z, VR_Q_Z, VR_STATE(X_WZ), VR_DER(X_WZ), VR_Q_X};
    double o[5];
    OKAY(f->get_real(c, ov, 5, o));
    CHECK(o[0] == x[X_WZ] && o[2] == x[X_WZ] && fabs(o[1] - x[X_QZ]) < 1e-6 && o[4] == 0.0, "outputs = states");
    CHECK(fabs(o[3] - tau / iz) <= 1e-15, "der(state_w_z) by value reference");
    OKAY(f->terminate(c));
    /* after fmi2Terminate the ME getters are allowed (FMI 2.0 state table), the rest is refused */
    OKAY(f->get_derivatives(c, dx, NX));
    OKAY(f->get_states(c, x, NX));
    me_wrong_state(f, c, NX, "Terminated");
    REFUSED(f->set_states(c, x, NX), "fmi2SetContinuousStates", "Terminated");
    f->free_instance(c);
    return events;
}

/* serialized FMU state of `s` (freed by the caller) */
static unsigned char *ser(const Fmi *f, C c, void *s, size_t *n) {
    OKAY(f->ser_size(c, s, n));
    unsigned char *b = malloc(*n);
    OKAY(f->serialize(c, s, (char *)b, *n));
    return b;
}

/* a restored ME state is refused or usable: the getters answer OK with finite values or Error */
static int me_try_state(const Fmi *f, C c, const unsigned char *b, size_t n) {
    void *s = NULL;
    last_msg[0] = 0;
    St st = f->deserialize(c, (const char *)b, n, &s);
    if (st != OK) {
        CHECK(st == ERROR && strstr(last_msg, "fmi2DeSerializeFMUstate"), "deserialize: neither OK nor Error with a message");
        return 0;
    }
    CHECK(f->set_state(c, s) == OK, "set an accepted state");
    double x[NX], dx[NX];
    St g = f->get_states(c, x, NX);
    CHECK(g == OK || g == ERROR, "get states after restore");
    if (g == OK) for (int i = 0; i < NX; i++) CHECK(isfinite(x[i]), "fmi2OK with a non-finite state");
    g = f->get_derivatives(c, dx, NX);
    CHECK(g == OK || g == ERROR, "get derivatives after restore");
    if (g == OK) for (int i = 0; i < NX; i++) CHECK(isfinite(dx[i]), "fmi2OK with a non-finite derivative");
    St e = f->enter_event_mode(c);
    CHECK(e == OK || e == ERROR, "enter event mode after restore");
    if (e == OK) {
        EventInfo ei;
        St d = f->new_discrete_states(c, &ei);
        CHECK(d == OK || d == ERROR, "event iteration after restore");
        if (d == OK) CHECK(!ei.next_event_time_defined || isfinite(ei.next_event_time), "next event time finite");
    }
    CHECK(f->free_state(c, &s) == OK, "free state");
    return 1;
}

/* FMU states in event and continuous-time mode, corrupted ones, across ME and CS instances */
static int me_states(const Fmi *f, int n_fuzz) {
    C c = instance_of_type(f, "states", 0);
    unsigned vr[4] = {VR_INIT_W_X, VR_FAULT_TIME, VR_NOISE_STD_X, VR_NOISE_HOLD};
    double v[4] = {0.05, 0.7071, 1e-3, 0.25};
    init_with(f, c, vr, v, 4);
    double tnext, x[NX], dx[NX];
    void *s_ev = NULL, *s_ct = NULL;
    OKAY(f->get_state(c, &s_ev)); /* event mode, before the first event iteration */
    event_iteration(f, c, &tnext);
    CHECK(tnext == 0.25, "first noise-hold boundary");
    OKAY(f->enter_ct_mode(c));
    /* Euler to the fault time 0.7071 through the events at 0.25, 0.5 */
    OKAY(f->get_states(c, x, NX));
    double t = 0.0;
    while (t < 0.7071) {
        OKAY(f->get_derivatives(c, dx, NX));
        double t1 = fmin(t + 0.01, tnext);
        euler_step(f, c, NX, x, dx, t, t1, &tnext);
        t = t1;
    }
    CHECK(t == 0.7071 && tnext == 0.75, "at the fault time, next boundary 0.75");
    OKAY(f->set_time(c, 0.72));
    OKAY(f->get_state(c, &s_ct)); /* continuous-time mode at 0.72, last event at 0.7071 */
    double x_ct[NX], dx_ct[NX];
    OKAY(f->get_states(c, x_ct, NX));
    OKAY(f->get_derivatives(c, dx_ct, NX));
    /* the event-mode state brings event mode back: continuous-time calls are refused again */
    OKAY(f->set_state(c, s_ev));
    me_wrong_state(f, c, NX, "EventMode");
    event_iteration(f, c, &tnext);
    CHECK(tnext == 0.25, "next event after restoring the initial state");
    /* the continuous-time state: same states and derivatives, the same last event */
    OKAY(f->set_state(c, s_ct));
    OKAY(f->get_states(c, x, NX));
    OKAY(f->get_derivatives(c, dx, NX));
    CHECK(!memcmp(x, x_ct, sizeof x) && !memcmp(dx, dx_ct, sizeof dx), "restored states and derivatives");
    OKAY(f->set_time(c, 0.71));
    REFUSED(f->set_time(c, 0.70), "fmi2SetTime", "before the last event at t = 0.7071");
    /* serialize / deserialize (also into a second ME instance, whose own run is elsewhere) */
    size_t n;
    unsigned char *b = ser(f, c, s_ct, &n);
    C c2 = instance_of_type(f, "states2", 0);
    init_with(f, c2, vr, v, 4);
    void *s2 = NULL;
    OKAY(f->deserialize(c2, (const char *)b, n, &s2));
    OKAY(f->set_state(c2, s2));
    OKAY(f->get_states(c2, x, NX));
    OKAY(f->get_derivatives(c2, dx, NX));
    CHECK(!memcmp(x, x_ct, sizeof x) && !memcmp(dx, dx_ct, sizeof dx), "deserialized states and derivatives");
    REFUSED(f->set_time(c2, 0.70), "fmi2SetTime", "before the last event at t = 0.7071");
    OKAY(f->enter_event_mode(c2));
    OKAY(f->set_time(c2, 0.75));
    event_iteration(f, c2, &tnext);
    CHECK(tnext == 1.0, "next event of the restored run");
    /* a state reused as the target of fmi2GetFMUstate in event mode */
    OKAY(f->get_state(c2, &s2));
    REFUSED(f->set_time(c2, 0.74), "fmi2SetTime", "before the last event at t = 0.75");
    /* a Model Exchange state is refused by a Co-Simulation instance and the other way round */
    C cs = ready(f, 0);
    void *s_cs = NULL, *s_x = NULL;
    /* refused already when deserialized (an accepted state can always be set) */
    REFUSED(f->deserialize(cs, (const char *)b, n, &s_x), "fmi2DeSerializeFMUstate", "taken from a Model Exchange instance");
    REFUSED(f->set_state(cs, s2), "fmi2SetFMUstate", "taken from a Model Exchange instance");
    OKAY(f->get_state(cs, &s_cs));
    size_t ncs;
    unsigned char *bcs = ser(f, cs, s_cs, &ncs);
    void *s_y = NULL;
    REFUSED(f->deserialize(c, (const char *)bcs, ncs, &s_y), "fmi2DeSerializeFMUstate", "taken from a Co-Simulation instance");
    REFUSED(f->set_state(c, s_cs), "fmi2SetFMUstate", "taken from a Co-Simulation instance");
    /* ME calls on the Co-Simulation instance */
    int a, bb;
    EventInfo ei;
    REFUSED(f->set_time(cs, 1.0), "fmi2SetTime", "instantiated for Co-Simulation");
    REFUSED(f->enter_event_mode(cs), "fmi2EnterEventMode", "instantiated for Co-Simulation");
    REFUSED(f->new_discrete_states(cs, &ei), "fmi2NewDiscreteStates", "instantiated for Co-Simulation");
    REFUSED(f->enter_ct_mode(cs), "fmi2EnterContinuousTimeMode", "instantiated for Co-Simulation");
    REFUSED(f->completed_step(cs, 1, &a, &bb), "fmi2CompletedIntegratorStep", "instantiated for Co-Simulation");
    REFUSED(f->set_states(cs, x, NX), "fmi2SetContinuousStates", "instantiated for Co-Simulation");
    REFUSED(f->get_derivatives(cs, dx, NX), "fmi2GetDerivatives", "instantiated for Co-Simulation");
    REFUSED(f->get_indicators(cs, NULL, 0), "fmi2GetEventIndicators", "instantiated for Co-Simulation");
    REFUSED(f->get_states(cs, x, NX), "fmi2GetContinuousStates", "instantiated for Co-Simulation");
    REFUSED(f->get_nominals(cs, x, NX), "fmi2GetNominalsOfContinuousStates", "instantiated for Co-Simulation");
    free(bcs);
    f->free_instance(cs); /* s_cs and s_x go with it */
    /* corrupted serialized states */
    unsigned char *m = malloc(n);
    memcpy(m, b, n);
    m[n / 2] ^= 0x10; /* CRC no longer matches */
    REFUSED(f->deserialize(c, (const char *)m, n, &s_y), "fmi2DeSerializeFMUstate", "CRC");
    REFUSED(f->deserialize(c, (const char *)b, n - 1, &s_y), "fmi2DeSerializeFMUstate", "does not match its header");
    REFUSED(f->deserialize(c, NULL, n, &s_y), "fmi2DeSerializeFMUstate", "NULL");
    REFUSED(f->deserialize(c, (const char *)b, 0, &s_y), "fmi2DeSerializeFMUstate", "too short");
    REFUSED(f->deserialize(c, (const char *)b, n, NULL), "fmi2DeSerializeFMUstate", "NULL");
    /* the time of the last event (0.7071) made NaN or later than the time (0.72), with a valid CRC: refused.
       Its first copy is the run's (the run precedes the model, whose fault_time is 0.7071 too). */
    double evil[2] = {NAN, 0.9}, te = 0.7071;
    size_t at = 0;
    for (size_t i = 16; i + 8 <= n - 4 && !at; i++)
        if (!memcmp(b + i, &te, 8)) at = i;
    CHECK(at, "the time of the last event was not found in the serialized state");
    for (int k = 0; k < 2; k++) {
        memcpy(m, b, n);
        memcpy(m + at, &evil[k], 8);
        fix_crc(m, n);
        REFUSED(f->deserialize(c, (const char *)m, n, &s_y), "fmi2DeSerializeFMUstate", "time of the last event");
    }
    /* a state of format version 1 (before the time of the last event was stored) */
    memcpy(m, b, n);
    m[8] = 1;
    fix_crc(m, n);
    REFUSED(f->deserialize(c, (const char *)m, n, &s_y), "fmi2DeSerializeFMUstate", "format version 1");
    /* random mutations with a valid CRC: refused or usable */
    int accepted = 0;
    for (int i = 0; i < n_fuzz; i++) {
        memcpy(m, b, n);
        int flips = 1 + (int)(next() % 4);
        for (int k = 0; k < flips; k++) {
            size_t pos = 16 + next() % (n - 20);
            if (next() % 2) m[pos] ^= (unsigned char)(1u << (next() % 8)); else m[pos] = (unsigned char)next();
        }
        fix_crc(m, n);
        accepted += me_try_state(f, c, m, n);
    }
    /* freeing: NULL slot, foreign pointer */
    REFUSED(f->free_state(c, NULL), "fmi2FreeFMUstate", "NULL");
    void *foreign = m;
    REFUSED(f->set_state(c, foreign), "fmi2SetFMUstate", "not created by this FMU");
    OKAY(f->free_state(c, &s_ev));
    OKAY(f->free_state(c, &s_ev)); /* NULL after the first free: a no-op */
    free(m);
    free(b);
    f->free_instance(c2); /* s2 with it */
    f->free_instance(c);  /* s_ct with it */
    return accepted;
}

/* PdController value references (modelDescription/PdController.xml): inputs q 0-3, w 4-6, output torque_cmd 20-22 */
enum { LAW_Q_W = 0, LAW_W_X = 4, LAW_TORQUE_X = 20 };

/* the law's inputs at time t: a unit quaternion and a body rate */
static void law_inputs(double t, double *u) {
    double a = 0.3 * sin(t), ax[3] = {0.6, -0.48, 0.64};
    u[0] = cos(a / 2);
    for (int i = 0; i < 3; i++) u[1 + i] = sin(a / 2) * ax[i];
    u[4] = 0.1 * sin(2 * t); u[5] = -0.05 * cos(t); u[6] = 0.02;
}

/* an ME instance of AttitudePlant after a few Euler steps, with FMU states (freed with the instance) */
static C me_reload_instance(const Fmi *f, double *x) {
    C c = instance_of_type(f, "reload-me", 0);
    unsigned vr = VR_INIT_W_X;
    double w = 0.05, tnext, dx[NX], t = 0.0;
    init_with(f, c, &vr, &w, 1);
    event_iteration(f, c, &tnext);
    OKAY(f->enter_ct_mode(c));
    OKAY(f->get_states(c, x, NX));
    for (int k = 0; k < 20; k++, t += 0.01) {
        OKAY(f->get_derivatives(c, dx, NX));
        euler_step(f, c, NX, x, dx, t, t + 0.01, &tnext);
    }
    void *s = NULL, *s2 = NULL;
    OKAY(f->get_state(c, &s));
    size_t n;
    unsigned char *b = ser(f, c, s, &n);
    OKAY(f->deserialize(c, (const char *)b, n, &s2));
    OKAY(f->set_state(c, s2));
    free(b);
    return c;
}

/* ----- reuse mode: stale instance and FMU-state handles after their memory or slot went to a new one -----
 * Each round: instance a (stepped, two FMU states: s1 kept until a is freed, s2 freed on its own), a freed;
 * then instance b and its state sb, which an allocator gives a's and s1's/s2's memory most of the time. Every
 * stale handle kept so far (the thread's first ones, its last STALE_KEEP, and a pool shared by all threads)
 * must be refused with fmi2Error: instance calls with no message (no instance to log to), state calls on b
 * with a message naming the function; b's outputs must not move and its run must end where a fresh one ends. */
enum { STALE_KEEP = 24, STALE_POOL = 64 };
typedef struct { C c[STALE_POOL]; void *s[2 * STALE_POOL]; unsigned nc, ns; pthread_mutex_t lock; } StalePool;
static StalePool pool2 = {.lock = PTHREAD_MUTEX_INITIALIZER};
typedef struct {
    int n, same_addr, same_state;
    long refused;
    double ref;
    C first_c, c[STALE_KEEP];
    void *first_s, *s[2 * STALE_KEEP];
    unsigned nc, ns;
    const Fmi *f;
} Reuse2;

static void stale_refused(St got, const char *call, const char *fn, long *refused) {
    if (got == ERROR && (!fn || strstr(last_msg, fn))) { (*refused)++; return; }
    printf("FAIL %s with a stale handle returned %d (expected fmi2Error%s%s; last message: %s)\n", call, got,
           fn ? " and a message naming " : "", fn ? fn : "", last_msg);
    fflush(stdout);
    exit(1);
}

/* every call a stale instance handle could reach b through, and the stale states given to b */
static void stale_calls2(const Fmi *f, C b, C stale, void *s, long *refused) {
    unsigned in = VR_TORQUE_CMD_X, out = VR_W_X;
    double u = 1e3, w;
    if (stale) {
        stale_refused(f->do_step(stale, 0.05, 0.01, 1), "fmi2DoStep", NULL, refused);
        stale_refused(f->set_real(stale, &in, 1, &u), "fmi2SetReal", NULL, refused);
        stale_refused(f->get_real(stale, &out, 1, &w), "fmi2GetReal", NULL, refused);
        void *sx = NULL;
        stale_refused(f->get_state(stale, &sx), "fmi2GetFMUstate", NULL, refused);
        stale_refused(f->reset(stale), "fmi2Reset", NULL, refused);
        f->free_instance(stale); /* must be ignored */
    }
    if (s) {
        size_t n;
        void *copy = s;
        stale_refused(f->set_state(b, s), "fmi2SetFMUstate", "fmi2SetFMUstate", refused);
        stale_refused(f->ser_size(b, s, &n), "fmi2SerializedFMUstateSize", "fmi2SerializedFMUstateSize", refused);
        stale_refused(f->free_state(b, &copy), "fmi2FreeFMUstate", "fmi2FreeFMUstate", refused);
    }
}

static void reuse_round2(Reuse2 *r) {
    const Fmi *f = r->f;
    C a = ready(f, 0);
    double t = 0;
    step_n(f, a, &t, 3);
    void *s1 = NULL, *s2 = NULL;
    CHECK(f->get_state(a, &s1) == OK && f->get_state(a, &s2) == OK, "get states of a");
    void *s2_stale = s2;
    CHECK(f->free_state(a, &s2) == OK && !s2, "free state s2");
    f->free_instance(a); /* frees s1 with it */
    C b = ready(f, 0);
    void *sb = NULL;
    CHECK(f->get_state(b, &sb) == OK, "get state of b");
    r->same_addr += b == a;
    r->same_state += sb == s1 || sb == s2_stale;
    t = 0;
    step_n(f, b, &t, 5);
    double w = read_wx(f, b);
    if (!r->first_c) { r->first_c = a; r->first_s = s1; }
    r->c[r->nc++ % STALE_KEEP] = a;
    r->s[r->ns++ % (2 * STALE_KEEP)] = s1;
    r->s[r->ns++ % (2 * STALE_KEEP)] = s2_stale;
    pthread_mutex_lock(&pool2.lock);
    pool2.c[pool2.nc++ % STALE_POOL] = a;
    pool2.s[pool2.ns++ % (2 * STALE_POOL)] = s1;
    C shared_c[8];
    void *shared_s[8];
    int k_shared = pool2.nc < 8 ? (int)pool2.nc : 8;
    for (int k = 0; k < k_shared; k++) {
        shared_c[k] = pool2.c[(unsigned)next() % (pool2.nc < STALE_POOL ? pool2.nc : STALE_POOL)];
        shared_s[k] = pool2.s[(unsigned)next() % (pool2.ns < 2 * STALE_POOL ? pool2.ns : 2 * STALE_POOL)];
    }
    pthread_mutex_unlock(&pool2.lock);
    stale_calls2(f, b, r->first_c, r->first_s, &r->refused);
    for (unsigned k = 0; k < r->nc && k < STALE_KEEP; k++) stale_calls2(f, b, r->c[k], NULL, &r->refused);
    for (unsigned k = 0; k < r->ns && k < 2 * STALE_KEEP; k++) stale_calls2(f, b, NULL, r->s[k], &r->refused);
    for (int k = 0; k < k_shared; k++) stale_calls2(f, b, shared_c[k], shared_s[k], &r->refused);
    /* b untouched: the same output, and the rest of its run ends where a fresh run ends */
    CHECK(read_wx(f, b) == w, "a stale handle changed the new instance's output");
    step_n(f, b, &t, 5);
    CHECK(read_wx(f, b) == r->ref, "the new instance's run differs from a fresh one");
    CHECK(f->free_state(b, &sb) == OK, "free state of b");
    f->free_instance(b);
}

static void *reuse_worker2(void *arg) {
    Reuse2 *r = (Reuse2 *)arg;
    for (int i = 0; i < r->n; i++) reuse_round2(r);
    return NULL;
}

/* reuse N T HOLD: T threads, N rounds each, while HOLD other instances live (past the lock-free slots) */
static void reuse2(int n, int nt, int hold) {
    Fmi f = load();
    CHECK(nt > 0 && nt <= 64 && hold >= 0, "1 to 64 threads, HOLD >= 0");
    C *held = malloc(sizeof(C) * (size_t)(hold + 1));
    for (int i = 0; i < hold; i++) held[i] = ready(&f, 0);
    C c = ready(&f, 0);
    double t = 0;
    step_n(&f, c, &t, 10);
    double ref = read_wx(&f, c);
    f.free_instance(c);
    rng = 20261129;
    static Reuse2 r[64];
    pthread_t th[64];
    for (int i = 0; i < nt; i++) {
        r[i] = (Reuse2){.n = n, .ref = ref, .f = &f};
        CHECK(pthread_create(&th[i], NULL, reuse_worker2, &r[i]) == 0, "pthread_create");
    }
    long refused = 0;
    int same_addr = 0, same_state = 0;
    for (int i = 0; i < nt; i++) {
        pthread_join(th[i], NULL);
        refused += r[i].refused;
        same_addr += r[i].same_addr;
        same_state += r[i].same_state;
    }
    for (int i = 0; i < hold; i++) {
        CHECK(read_wx(&f, held[i]) == 0.05, "a held instance changed");
        f.free_instance(held[i]);
    }
    free(held);
    dlclose(f.lib);
    printf("ok reuse %d threads x %d rounds (%d other instances held): %ld stale calls refused; the new instance had "
           "the freed one's handle value in %d rounds, its state a freed state's in %d\n", nt, n, hold, refused,
           same_addr, same_state);
}

/* cross mode: two copies of the library under two file names (two loaded libraries, each with its own
   handle tables); each one's instance and FMU-state handles are refused by the other */
static void cross2(const char *lib2, int n) {
    Fmi a = load();
    const char *lib1 = LIB;
    LIB = lib2;
    Fmi b = load();
    LIB = lib1;
    CHECK(a.lib != b.lib, "the second copy is a second library");
    long refused = 0;
    for (int i = 0; i < n; i++) {
        C ca = ready(&a, 0), cb = ready(&b, 0);
        void *sa = NULL, *sb = NULL;
        CHECK(a.get_state(ca, &sa) == OK && b.get_state(cb, &sb) == OK, "get states");
        stale_calls2(&b, cb, ca, sa, &refused); /* a's handles given to b's library */
        stale_calls2(&a, ca, cb, sb, &refused);
        CHECK(read_wx(&a, ca) == 0.05 && read_wx(&b, cb) == 0.05, "an instance changed");
        CHECK(a.free_state(ca, &sa) == OK && b.free_state(cb, &sb) == OK, "free states");
        a.free_instance(ca);
        b.free_instance(cb);
    }
    dlclose(a.lib);
    dlclose(b.lib);
    printf("ok cross %d rounds: %ld calls with the other library's handles refused\n", n, refused);
}


/* ----- epoch: start times far from 0 (issue 45) -----------------------------------------------------
 * Every call must return within a second (a watchdog timer ends the program naming the call) and either
 * work or be refused with Error and a message naming the function (and, for the time bound, "2^53"). */
static const double EPOCHS[] = {1e6, -1e6, 1e10, -1e10, 1e15, -1e15, 1e18, -1e18, 1e20, -1e20,
                                1e100, -1e100, 1e300, -1e300};
enum { N_EPOCHS = sizeof EPOCHS / sizeof EPOCHS[0] };
static const char *volatile watched = "";
static double watched_t;
static void watchdog(int sig) {
    (void)sig;
    char b[256];
    int n = snprintf(b, sizeof b, "FAIL %s at startTime %g did not return within 1 s\n", watched, watched_t);
    if (write(1, b, (size_t)n) < 0) _exit(3);
    _exit(1);
}
static void watch(const char *fn, double t0) {
    struct itimerval it = {{0, 0}, {1, 0}};
    watched = fn;
    watched_t = t0;
    signal(SIGALRM, watchdog);
    setitimer(ITIMER_REAL, &it, NULL);
}
static void unwatch(void) {
    struct itimerval it = {{0, 0}, {0, 0}};
    setitimer(ITIMER_REAL, &it, NULL);
}
static int n_epoch_calls, n_epoch_refused, n_epoch_bound;
/* one timed call: OK, or Error with a message naming fn; returns the status */
static St epoch_call(St st, const char *fn, double t0) {
    unwatch();
    n_epoch_calls++;
    if (st == OK || st == WARNING) return OK;
    if (st != ERROR || !strstr(last_msg, fn)) {
        printf("FAIL %s at startTime %g returned %d with message \"%s\" (expected OK, or Error naming it)\n", fn, t0,
               st, last_msg);
        fflush(stdout);
        exit(1);
    }
    n_epoch_refused++;
    if (strstr(last_msg, "2^53")) n_epoch_bound++;
    return ERROR;
}
#define TIMED(fn, t0, call) (last_msg[0] = 0, watch(fn, t0), epoch_call((call), fn, t0))

static void epoch2(const Fmi *f, double h) {
    for (int i = 0; i < N_EPOCHS; i++) {
        double t0 = EPOCHS[i];
        C c = f->instantiate("epoch", 1, GUID, NULL, &CB, 0, 0);
        CHECK(c, "instantiate");
        if (TIMED("fmi2SetupExperiment", t0, f->setup(c, 0, 0.0, t0, 0, 0.0)) == OK &&
            TIMED("fmi2EnterInitializationMode", t0, f->enter_init(c)) == OK &&
            TIMED("fmi2ExitInitializationMode", t0, f->exit_init(c)) == OK &&
            TIMED("fmi2DoStep", t0, f->do_step(c, t0, h, 1)) == OK) {
            TIMED("fmi2DoStep", t0, f->do_step(c, t0 + h, h, 1));
        }
        f->free_instance(c);
    }
}

static int main2(int argc, char **argv) {
    if (argc < 4) { fprintf(stderr, "usage: %s LIB GUID MODE ...\n", argv[0]); return 2; }
    LIB = argv[1]; GUID = argv[2];
    const char *mode = argv[3];
    if (!strcmp(mode, "epoch")) {
        Fmi f = load();
        epoch2(&f, argc > 4 ? atof(argv[4]) : 0.1);
        dlclose(f.lib);
        printf("ok epoch: %d calls returned within 1 s, %d refused with Error naming the function (%d naming the 2^53 bound)\n",
               n_epoch_calls, n_epoch_refused, n_epoch_bound);
    } else if (!strcmp(mode, "cycles")) {
        int n = atoi(argv[4]);
        Fmi f = load();
        double w0 = cycle(&f, 0);
        for (int i = 1; i < n; i++) CHECK(cycle(&f, i % 2) == w0, "cycles not bit-identical");
        dlclose(f.lib);
        printf("ok cycles %d w_x %.17g\n", n, w0);
    } else if (!strcmp(mode, "reload")) {
        int n = atoi(argv[4]);
        double w0 = 0.0;
        for (int i = 0; i < n; i++) {
            Fmi f = load();
            double w = cycle(&f, 1);
            if (i == 0) w0 = w; else CHECK(w == w0, "reload not bit-identical");
            CHECK(dlclose(f.lib) == 0, "dlclose");
        }
        printf("ok reload %d\n", n);
    } else if (!strcmp(mode, "threads")) {
        int nt = atoi(argv[4]), n = atoi(argv[5]);
        CHECK(nt > 0 && nt <= 64, "1 to 64 threads");
        Fmi f = load();
        double ref = cycle(&f, 1);
        pthread_t th[64];
        Work w[64];
        for (int i = 0; i < nt; i++) {
            w[i] = (Work){&f, n, ref, 0};
            CHECK(pthread_create(&th[i], NULL, worker, &w[i]) == 0, "pthread_create");
        }
        for (int i = 0; i < nt; i++) pthread_join(th[i], NULL);
        for (int i = 0; i < nt; i++) CHECK(w[i].bad == 0, "a thread's result differs from the single-threaded run");
        dlclose(f.lib);
        printf("ok threads %d x %d cycles, all bit-identical to the single-threaded run\n", nt, n);
    } else if (!strcmp(mode, "reuse")) {
        reuse2(atoi(argv[4]), argc > 5 ? atoi(argv[5]) : 1, argc > 6 ? atoi(argv[6]) : 0);
    } else if (!strcmp(mode, "cross")) {
        cross2(argv[4], atoi(argv[5]));
    } else if (!strcmp(mode, "race")) {
        int n = atoi(argv[4]);
        Fmi f = load();
        C c = ready(&f, 0);
        Racer r[2] = {{&f, c, n, 1}, {&f, c, n, 0}};
        pthread_t th[2];
        for (int i = 0; i < 2; i++) CHECK(pthread_create(&th[i], NULL, racer, &r[i]) == 0, "pthread_create");
        for (int i = 0; i < 2; i++) pthread_join(th[i], NULL);
        f.free_instance(c);
        dlclose(f.lib);
        printf("ok race %d calls per thread on one instance (misuse)\n", n);
    } else if (!strcmp(mode, "hang")) {
        Fmi f = load();
        /* 1. a tiny internal step is refused at initialization (declared range) */
        C c = f.instantiate("h1", 1, GUID, NULL, &CB, 0, 0);
        f.setup(c, 0, 0, 0, 0, 0); f.enter_init(c);
        unsigned vr = VR_MAX_STEP; double v = 1e-300;
        CHECK(f.set_real(c, &vr, 1, &v) == OK, "set max step");
        CHECK(f.exit_init(c) == ERROR, "max_internal_step = 1e-300 accepted");
        /* 2. the smallest allowed step with a long communication step is refused before the work */
        v = 1e-6; f.set_real(c, &vr, 1, &v);
        CHECK(f.exit_init(c) == OK, "exit init with 1e-6");
        CHECK(f.do_step(c, 0.0, 10.0, 1) == ERROR, "doStep needing 1e7 internal steps accepted");
        f.free_instance(c);
        /* 3. default parameters, a step of 1e12 s */
        c = ready(&f, 0);
        CHECK(f.do_step(c, 0.0, 1e12, 1) == ERROR, "doStep(0, 1e12) accepted");
        f.free_instance(c);
        /* 4. adaptive integrator with an absurd tolerance: bounded */
        c = f.instantiate("h4", 1, GUID, NULL, &CB, 0, 0);
        f.setup(c, 1, 1e-300, 0.0, 0, 0.0); f.enter_init(c);
        unsigned iv = VR_INTEGRATOR; int two = 2;
        f.set_integer(c, &iv, 1, &two);
        unsigned wv = VR_INIT_W_X; double w = 0.1; f.set_real(c, &wv, 1, &w);
        CHECK(f.exit_init(c) == OK, "exit init DP");
        St st = f.do_step(c, 0.0, 1e6, 1);
        CHECK(st == OK || st == ERROR, "DP long step");
        f.free_instance(c);
        /* 5. a serialized state whose stored internal step is changed (CRC recomputed) is refused */
        c = ready(&f, 0);
        double t = 0; step_n(&f, c, &t, 3);
        void *s = NULL; f.get_state(c, &s);
        size_t n; unsigned char *b = (unsigned char *)serialize(&f, c, s, &n);
        double small = 0.01, evil = 1e-22; int found = 0;
        for (size_t i = 16; i + 8 <= n - 4; i++) {
            if (memcmp(b + i, &small, 8)) continue;
            found++;
            unsigned char *m = malloc(n); memcpy(m, b, n); memcpy(m + i, &evil, 8); fix_crc(m, n);
            void *s2 = NULL;
            CHECK(f.deserialize(c, (char *)m, n, &s2) == ERROR, "state with a changed internal step accepted");
            free(m);
        }
        CHECK(found >= 2, "the internal step value was not found in the payload");
        free(b); f.free_instance(c);
        dlclose(f.lib);
        printf("ok hang (%d stored copies of the step refused)\n", found);
    } else if (!strcmp(mode, "fuzz")) {
        int n = atoi(argv[4]); rng = strtoull(argv[5], NULL, 10) | 1;
        Fmi f = load();
        C c = ready(&f, 1);
        double t = 0; step_n(&f, c, &t, 7);
        void *s = NULL; f.get_state(c, &s);
        size_t len; unsigned char *b = (unsigned char *)serialize(&f, c, s, &len);
        int accepted = 0;
        unsigned char *m = malloc(len);
        for (int i = 0; i < n; i++) {
            memcpy(m, b, len);
            int flips = 1 + (int)(next() % 4);
            for (int k = 0; k < flips; k++) {
                size_t at = 16 + next() % (len - 20);
                if (next() % 2) m[at] ^= (unsigned char)(1u << (next() % 8)); else m[at] = (unsigned char)next();
            }
            fix_crc(m, len);
            try_state(&f, c, m, len, &accepted);
        }
        /* the instance is still usable afterwards */
        CHECK(f.set_state(c, s) == OK, "restore the original state");
        free(m); free(b); f.free_instance(c); dlclose(f.lib);
        printf("ok fuzz %d mutations, %d accepted and usable\n", n, accepted);
    } else if (!strcmp(mode, "extreme")) {
        Fmi f = load();
        struct { unsigned vr[2]; double v[2]; int n; const char *what; } cases[] = {
            {{VR_ORBIT_RADIUS}, {1e-110}, 1, "orbit_radius = 1e-110 (orbit_rate = inf)"},
            {{VR_WHEEL_COEFF, VR_WHEEL_CURRENT}, {1e300, 1e300}, 2, "wheel torque limit 1e600"},
        };
        for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
            C c = f.instantiate("x", 1, GUID, NULL, &CB, 0, 0);
            f.setup(c, 0, 0, 0, 0, 0); f.enter_init(c);
            CHECK(f.set_real(c, cases[i].vr, cases[i].n, cases[i].v) == OK, "set extreme");
            if (f.exit_init(c) != ERROR) die(cases[i].what);
            f.free_instance(c);
        }
        /* huge but finite commands: outputs finite or an error, never OK with inf */
        C c = ready(&f, 0);
        unsigned vr = VR_TORQUE_CMD_X; double u = 1e308;
        f.set_real(c, &vr, 1, &u);
        St st = f.do_step(c, 0.0, 0.01, 1);
        unsigned ov = VR_W_X; double w;
        St g = f.get_real(c, &ov, 1, &w);
        CHECK(st == ERROR || g == ERROR || isfinite(w), "fmi2OK with a non-finite output");
        f.free_instance(c);
        dlclose(f.lib);
        printf("ok extreme\n");
    } else if (!strcmp(mode, "me")) {
        int n_events = atoi(argv[4]), n_fuzz = atoi(argv[5]);
        rng = 20261124;
        Fmi f = load();
        me_bad_components(&f);
        /* the life cycle of an ME instance, with the calls each state refuses */
        C c = instance_of_type(&f, "me", 0);
        double x[NX], x0[NX], dx[NX], tnext;
        me_wrong_state(&f, c, NX, "Instantiated");
        OKAY(f.get_nominals(c, x, NX)); /* allowed before initialization */
        OKAY(f.setup(c, 0, 0.0, 0.0, 0, 0.0));
        OKAY(f.enter_init(c));
        me_wrong_state(&f, c, NX, "InitializationMode");
        OKAY(f.get_states(c, x, NX));
        CHECK(x[X_QW] == 1.0, "initial q_w");
        OKAY(f.get_indicators(c, NULL, 0));
        OKAY(f.exit_init(c));
        me_wrong_state(&f, c, NX, "EventMode");
        REFUSED(f.new_discrete_states(c, NULL), "fmi2NewDiscreteStates", "fmi2EventInfo is NULL");
        event_iteration(&f, c, &tnext);
        CHECK(isinf(tnext), "no time event with the default parameters");
        OKAY(f.enter_ct_mode(c));
        me_wrong_state(&f, c, NX, "ContinuousTimeMode");
        me_bad_pointers(&f, c, NX);
        /* NaN and Inf states and times: refused, the instance unchanged */
        OKAY(f.get_states(c, x0, NX));
        memcpy(x, x0, sizeof x);
        const double bad[3] = {NAN, INFINITY, -INFINITY};
        const int at[4] = {X_QW, X_QZ, X_WZ, NX - 1};
        for (int i = 0; i < 3; i++) {
            for (int k = 0; k < 4; k++) {
                x[at[k]] = bad[i];
                REFUSED(f.set_states(c, x, NX), "fmi2SetContinuousStates", "is not finite");
                x[at[k]] = x0[at[k]];
            }
            REFUSED(f.set_time(c, bad[i]), "fmi2SetTime", "is not finite");
        }
        OKAY(f.get_states(c, x, NX));
        CHECK(!memcmp(x, x0, sizeof x), "refused states left the instance unchanged");
        /* huge finite states: finite derivatives with fmi2OK, or fmi2Error with a message */
        x[X_WX] = 1e200;
        x[X_WY] = -1e200;
        OKAY(f.set_states(c, x, NX));
        last_msg[0] = 0;
        St st = f.get_derivatives(c, dx, NX);
        if (st == OK) for (int i = 0; i < NX; i++) CHECK(isfinite(dx[i]), "fmi2OK with a non-finite derivative");
        else CHECK(st == ERROR && strstr(last_msg, "fmi2GetDerivatives"), "huge states: neither finite nor a message");
        OKAY(f.set_states(c, x0, NX));
        /* time going backwards: behind the accepted point but after the last event is allowed, before it not */
        OKAY(f.set_time(c, 2.0));
        OKAY(f.set_time(c, 1.0));
        REFUSED(f.set_time(c, -0.5), "fmi2SetTime", "before the last event at t = 0");
        OKAY(f.set_time(c, 2.0));
        OKAY(f.enter_event_mode(c));
        event_iteration(&f, c, &tnext);
        REFUSED(f.set_time(c, 1.5), "fmi2SetTime", "before the last event at t = 2"); /* event mode */
        OKAY(f.enter_ct_mode(c));
        REFUSED(f.set_time(c, 1.999), "fmi2SetTime", "before the last event at t = 2");
        OKAY(f.set_time(c, 2.0 - 1e-12)); /* round-off below the event */
        OKAY(f.set_time(c, 2.0));
        /* very many event iterations at one instant, and many event/continuous-time switches */
        OKAY(f.enter_event_mode(c));
        OKAY(f.enter_event_mode(c)); /* allowed in event mode */
        int changed = 0;
        for (int i = 0; i < n_events; i++) {
            EventInfo ei;
            OKAY(f.new_discrete_states(c, &ei));
            CHECK(!ei.new_discrete_states_needed && !ei.terminate_simulation && !ei.next_event_time_defined, "event info");
            changed += ei.values_changed;
        }
        CHECK(changed <= 1, "the event update keeps changing the states");
        OKAY(f.enter_ct_mode(c));
        double t = 2.0;
        for (int i = 0; i < n_events; i++) {
            t = 2.0 + (i + 1) * 1e-3;
            OKAY(f.set_time(c, t));
            OKAY(f.enter_event_mode(c));
            event_iteration(&f, c, &tnext);
            OKAY(f.enter_ct_mode(c));
        }
        REFUSED(f.set_time(c, t - 1e-3), "fmi2SetTime", "before the last event");
        OKAY(f.get_states(c, x, NX));
        CHECK(!memcmp(x, x0, sizeof x), "event iterations changed a unit quaternion at rest");
        /* reset: instantiated again, and a new run */
        OKAY(f.reset(c));
        me_wrong_state(&f, c, NX, "Instantiated");
        init_with(&f, c, NULL, NULL, 0);
        event_iteration(&f, c, &tnext);
        OKAY(f.enter_ct_mode(c));
        OKAY(f.set_time(c, 0.0));
        OKAY(f.terminate(c));
        REFUSED(f.terminate(c), "fmi2Terminate", "Terminated");
        f.free_instance(c);
        int accepted = me_states(&f, n_fuzz);
        int proj = 0;
        int events = me_euler_run(&f, 1e-3, 3.0, &proj);
        CHECK(proj > 10, "no projection events in the Euler run");
        dlclose(f.lib);
        printf("ok me: %d refused calls with status and message checked, %d event iterations, %d of %d mutated ME "
               "states accepted and usable, Euler run with %d events (%d projections)\n", n_checked, 2 * n_events, accepted,
               n_fuzz, events, proj);
    } else if (!strcmp(mode, "me-reload")) {
        int n = atoi(argv[4]);
        double w0 = 0.0, x0[NX], x[NX];
        for (int i = 0; i < n; i++) {
            Fmi f = load();
            C me = me_reload_instance(&f, x);
            double w = cycle(&f, 1); /* a Co-Simulation cycle while the ME instance lives */
            if (i == 0) { w0 = w; memcpy(x0, x, sizeof x); }
            CHECK(w == w0 && !memcmp(x, x0, sizeof x), "reload not bit-identical");
            f.free_instance(me);
            CHECK(dlclose(f.lib) == 0, "dlclose");
        }
        printf("ok me-reload %d\n", n);
    } else if (!strcmp(mode, "me-law")) {
        int n = atoi(argv[4]);
        Fmi f = load();
        me_bad_components(&f);
        C c = instance_of_type(&f, "law-me", 0);
        double tnext;
        me_wrong_state(&f, c, 0, "Instantiated");
        OKAY(f.get_nominals(c, NULL, 0));
        OKAY(f.setup(c, 0, 0.0, 0.0, 0, 0.0));
        OKAY(f.enter_init(c));
        me_wrong_state(&f, c, 0, "InitializationMode");
        OKAY(f.get_states(c, NULL, 0));
        OKAY(f.exit_init(c));
        me_wrong_state(&f, c, 0, "EventMode");
        REFUSED(f.new_discrete_states(c, NULL), "fmi2NewDiscreteStates", "fmi2EventInfo is NULL");
        CHECK(!event_iteration(&f, c, &tnext) && isinf(tnext), "a static law has no events");
        OKAY(f.enter_ct_mode(c));
        me_wrong_state(&f, c, 0, "ContinuousTimeMode");
        me_bad_pointers(&f, c, 0);
        REFUSED(f.set_time(c, NAN), "fmi2SetTime", "is not finite");
        /* the same inputs into a Co-Simulation instance: the same outputs, bit for bit */
        C cs = instance_of_type(&f, "law-cs", 1);
        init_with(&f, cs, NULL, NULL, 0);
        unsigned in[7] = {LAW_Q_W, LAW_Q_W + 1, LAW_Q_W + 2, LAW_Q_W + 3, LAW_W_X, LAW_W_X + 1, LAW_W_X + 2};
        unsigned out[3] = {LAW_TORQUE_X, LAW_TORQUE_X + 1, LAW_TORQUE_X + 2};
        void *s = NULL;
        double u[7], y_me[3], y_cs[3], y_saved[3] = {0}, t_saved = 0;
        for (int i = 0; i < n; i++) {
            double t = i * 0.01;
            int enter = -1, term = -1;
            law_inputs(t, u);
            OKAY(f.set_time(c, t));
            OKAY(f.set_real(c, in, 7, u));
            OKAY(f.set_states(c, NULL, 0));
            OKAY(f.get_derivatives(c, NULL, 0));
            OKAY(f.completed_step(c, 1, &enter, &term));
            CHECK(enter == 0 && term == 0, "a static law asks for no event");
            OKAY(f.get_real(c, out, 3, y_me));
            OKAY(f.set_real(cs, in, 7, u));
            OKAY(f.get_real(cs, out, 3, y_cs));
            OKAY(f.do_step(cs, t, 0.01, 1));
            CHECK(!memcmp(y_me, y_cs, sizeof y_me), "ME and CS outputs differ");
            for (int k = 0; k < 3; k++) CHECK(isfinite(y_me[k]), "finite torque");
            if (i % 10 == 9) { /* an external event now and then (the inputs changed discontinuously) */
                OKAY(f.enter_event_mode(c));
                event_iteration(&f, c, &tnext);
                OKAY(f.enter_ct_mode(c));
            }
            if (i == n / 2) {
                OKAY(f.get_state(c, &s));
                memcpy(y_saved, y_me, sizeof y_me);
                t_saved = t;
            }
        }
        /* FMU state in continuous-time mode: serialized, restored, the same outputs; corrupted: refused */
        size_t len;
        unsigned char *b = ser(&f, c, s, &len);
        void *s2 = NULL;
        OKAY(f.deserialize(c, (const char *)b, len, &s2));
        OKAY(f.set_state(c, s2));
        OKAY(f.get_real(c, out, 3, y_me));
        CHECK(!memcmp(y_me, y_saved, sizeof y_me), "restored law outputs");
        REFUSED(f.set_time(c, t_saved - 1.0), "fmi2SetTime", "before the last event");
        b[len / 2] ^= 1;
        REFUSED(f.deserialize(c, (const char *)b, len, &s2), "fmi2DeSerializeFMUstate", "CRC");
        b[len / 2] ^= 1;
        void *s3 = NULL;
        REFUSED(f.deserialize(cs, (const char *)b, len, &s3), "fmi2DeSerializeFMUstate", "taken from a Model Exchange instance");
        REFUSED(f.set_state(cs, s2), "fmi2SetFMUstate", "taken from a Model Exchange instance");
        REFUSED(f.set_time(cs, 0.0), "fmi2SetTime", "instantiated for Co-Simulation");
        REFUSED(f.get_derivatives(cs, NULL, 0), "fmi2GetDerivatives", "instantiated for Co-Simulation");
        free(b);
        OKAY(f.terminate(c));
        OKAY(f.get_derivatives(c, NULL, 0));
        OKAY(f.get_states(c, NULL, 0));
        me_wrong_state(&f, c, 0, "Terminated");
        f.free_instance(cs);
        f.free_instance(c);
        dlclose(f.lib);
        printf("ok me-law: %d refused calls with status and message checked, %d steps equal to Co-Simulation\n", n_checked, n);
    } else {
        fprintf(stderr, "unknown mode %s\n", mode);
        return 2;
    }
    return 0;
}

/* ===== FMI 3.0 ====================================================================================== */
#undef EXPECT

typedef void *I;
enum { VR_MTQ_ENABLE = 144, VR_INERTIA_XX = 100 }; /* and VR_TORQUE_CMD_X, VR_W_X, VR_INIT_W_X above */
/* Model Exchange (modelDescription/fmi3/AttitudePlant.xml): 18 states, state k at 1000000000 + k, its
 * derivative at 1000100000 + k; state 9 is state_w_x */
enum { K_W_X = 9 }; /* NX = 18 above */
static const unsigned VR_STATE0 = 1000000000u, VR_DER0 = 1000100000u;
static const unsigned TIME_VR = 2147483647u;

typedef void (*Log3)(void *, int, const char *, const char *);
typedef I (*Inst3)(const char *, const char *, const char *, bool, bool, bool, bool, const unsigned *, size_t, void *, Log3, void *);

static int n_msgs;

static void log3(void *env, int status, const char *cat, const char *msg) {
    (void)env; (void)cat;
    if (getenv("HOSTILE_VERBOSE")) fprintf(stderr, "[%d] %s\n", status, msg);
    snprintf(last_msg, sizeof last_msg, "%s", msg);
    n_msgs++;
}

/* status st and a fresh log message containing func */
#define EXPECT(call, st, func) do { last_msg[0] = 0; St r_ = (call); \
    if (r_ != (st)) { char b_[256]; snprintf(b_, sizeof b_, "%s returned %d, expected %d", func, r_, st); die(b_); } \
    if ((st) >= ERROR && !strstr(last_msg, func)) { char b_[256]; snprintf(b_, sizeof b_, "%s logged no message naming it", func); die(b_); } } while (0)

static void *lib3;
static void *sym3(const char *name) {
    void *p = dlsym(lib3, name);
    if (!p) { printf("FAIL missing symbol %s\n", name); exit(1); }
    return p;
}

static Inst3 instantiate;
static void (*free_instance)(I);
static St (*enter_init)(I, bool, double, double, bool, double);
static St (*exit_init)(I);
static St (*terminate_)(I);
static St (*reset)(I);
static St (*get_f64)(I, const unsigned *, size_t, double *, size_t);
static St (*set_f64)(I, const unsigned *, size_t, const double *, size_t);
static St (*set_bool)(I, const unsigned *, size_t, const uint8_t *, size_t);
static St (*set_i32)(I, const unsigned *, size_t, const int32_t *, size_t);
static St (*do_step)(I, double, double, bool, bool *, bool *, bool *, double *);
static St (*get_state)(I, void **);
static St (*set_state)(I, void *);
static St (*free_state)(I, void **);
static St (*ser_size)(I, void *, size_t *);
static St (*serialize3)(I, void *, uint8_t *, size_t);
static St (*deserialize)(I, const uint8_t *, size_t, void **);

static void load3(void) {
    lib3 = dlopen(LIB, RTLD_NOW | RTLD_LOCAL);
    if (!lib3) { printf("FAIL dlopen %s: %s\n", LIB, dlerror()); exit(1); }
    instantiate = (Inst3)sym3("fmi3InstantiateCoSimulation");
    free_instance = sym3("fmi3FreeInstance");
    enter_init = sym3("fmi3EnterInitializationMode");
    exit_init = sym3("fmi3ExitInitializationMode");
    terminate_ = sym3("fmi3Terminate");
    reset = sym3("fmi3Reset");
    get_f64 = sym3("fmi3GetFloat64");
    set_f64 = sym3("fmi3SetFloat64");
    set_bool = sym3("fmi3SetBoolean");
    set_i32 = sym3("fmi3SetInt32");
    do_step = sym3("fmi3DoStep");
    get_state = sym3("fmi3GetFMUState");
    set_state = sym3("fmi3SetFMUState");
    free_state = sym3("fmi3FreeFMUState");
    ser_size = sym3("fmi3SerializedFMUStateSize");
    serialize3 = sym3("fmi3SerializeFMUState");
    deserialize = sym3("fmi3DeserializeFMUState");
}

static I ready3(void) {
    I c = instantiate("hostile3", GUID, NULL, false, false, false, false, NULL, 0, NULL, log3, NULL);
    CHECK(c, "fmi3InstantiateCoSimulation");
    unsigned vr = VR_INIT_W_X;
    double v = 0.05;
    CHECK(set_f64(c, &vr, 1, &v, 1) == OK, "set init_w_x");
    CHECK(enter_init(c, false, 0.0, 0.0, true, 100.0) == OK, "enter init");
    CHECK(exit_init(c) == OK, "exit init");
    return c;
}

static St step3(I c, double t, double h) {
    bool ev = true, term = true, early = true;
    double last = -1;
    St s = do_step(c, t, h, false, &ev, &term, &early, &last);
    if (s == OK) CHECK(!ev && !term && !early && last == t + h, "fmi3DoStep outputs");
    return s;
}

typedef I (*InstMe)(const char *, const char *, const char *, bool, bool, void *, Log3);
static InstMe inst_me;
static St (*enter_ct)(I);
static St (*enter_ev)(I);
static St (*update_ds)(I, bool *, bool *, bool *, bool *, bool *, double *);
static St (*completed)(I, bool, bool *, bool *);
static St (*set_time)(I, double);
static St (*set_x)(I, const double *, size_t);
static St (*get_x)(I, double *, size_t);
static St (*get_dx)(I, double *, size_t);
static St (*get_nom)(I, double *, size_t);
static St (*get_z)(I, double *, size_t);
static St (*n_states)(I, size_t *);
static St (*n_indicators)(I, size_t *);

static void load_me(void) {
    inst_me = (InstMe)sym3("fmi3InstantiateModelExchange");
    enter_ct = sym3("fmi3EnterContinuousTimeMode");
    enter_ev = sym3("fmi3EnterEventMode");
    update_ds = sym3("fmi3UpdateDiscreteStates");
    completed = sym3("fmi3CompletedIntegratorStep");
    set_time = sym3("fmi3SetTime");
    set_x = sym3("fmi3SetContinuousStates");
    get_x = sym3("fmi3GetContinuousStates");
    get_dx = sym3("fmi3GetContinuousStateDerivatives");
    get_nom = sym3("fmi3GetNominalsOfContinuousStates");
    get_z = sym3("fmi3GetEventIndicators");
    n_states = sym3("fmi3GetNumberOfContinuousStates");
    n_indicators = sym3("fmi3GetNumberOfEventIndicators");
}

static St update(I c) {
    bool need = true, term = true, nom = true, val = true, def = true;
    double next = -1;
    return update_ds(c, &need, &term, &nom, &val, &def, &next);
}

/* an ME instance in Continuous-Time Mode with init_w_x = 0.05 */
static I ready_me(void) {
    I c = inst_me("hostile3me", GUID, NULL, false, false, NULL, log3);
    CHECK(c, "fmi3InstantiateModelExchange");
    unsigned vr = VR_INIT_W_X;
    double v = 0.05;
    CHECK(set_f64(c, &vr, 1, &v, 1) == OK, "set init_w_x");
    CHECK(enter_init(c, false, 0.0, 0.0, false, 0.0) == OK && exit_init(c) == OK, "ME init");
    CHECK(update(c) == OK && enter_ct(c) == OK, "ME event iteration");
    return c;
}

/* one Model Exchange instance: states, derivatives, an FMU state; freed with its state still held */
static void me_cycle(void) {
    I c = ready_me();
    double x[NX], dx[NX];
    CHECK(get_x(c, x, NX) == OK && get_dx(c, dx, NX) == OK, "ME get");
    CHECK(set_time(c, 0.5) == OK && set_x(c, x, NX) == OK, "ME set");
    void *s = NULL;
    CHECK(get_state(c, &s) == OK && s, "ME get state");
    free_instance(c); /* frees the state it still holds */
}

static double cycle3(void) {
    I c = ready3();
    unsigned vr = VR_TORQUE_CMD_X, out = VR_W_X;
    double tq = 0.5, w1, w2, t = 0;
    CHECK(set_f64(c, &vr, 1, &tq, 1) == OK, "set torque");
    for (int k = 0; k < 10; k++, t += 0.1) CHECK(step3(c, t, 0.1) == OK, "step3");
    void *s = NULL;
    CHECK(get_state(c, &s) == OK && s, "get state");
    size_t n = 0;
    CHECK(ser_size(c, s, &n) == OK && n > 0, "serialized size");
    uint8_t *buf = malloc(n);
    CHECK(serialize3(c, s, buf, n) == OK, "serialize3");
    CHECK(step3(c, t, 0.1) == OK, "step3 after state");
    CHECK(get_f64(c, &out, 1, &w1, 1) == OK, "get w_x");
    void *d = NULL;
    CHECK(deserialize(c, buf, n, &d) == OK && d, "deserialize");
    CHECK(set_state(c, d) == OK, "set state");
    CHECK(step3(c, t, 0.1) == OK, "step3 after restore");
    CHECK(get_f64(c, &out, 1, &w2, 1) == OK, "get w_x again");
    CHECK(memcmp(&w1, &w2, sizeof w1) == 0, "restored state steps to the same bits");
    CHECK(free_state(c, &s) == OK && s == NULL, "free state");
    CHECK(free_state(c, &d) == OK && d == NULL, "free state 2");
    free(buf);
    CHECK(terminate_(c) == OK, "terminate");
    free_instance(c);
    me_cycle();
    return w1;
}

static void abuse(void) {
    unsigned vr = VR_W_X, tvr = TIME_VR, in = VR_TORQUE_CMD_X;
    double v = 0, nan_ = NAN;
    bool b;
    double d;
    /* instantiation */
    CHECK(!instantiate(NULL, GUID, NULL, false, false, false, false, NULL, 0, NULL, log3, NULL), "NULL name accepted");
    CHECK(strstr(last_msg, "fmi3InstantiateCoSimulation") && strstr(last_msg, "instanceName"), "NULL name message");
    CHECK(!instantiate("x", NULL, NULL, false, false, false, false, NULL, 0, NULL, log3, NULL), "NULL token accepted");
    CHECK(!instantiate("x", "{bad}", NULL, false, false, false, false, NULL, 0, NULL, NULL, NULL), "bad token without logger");
    CHECK(!instantiate("x", GUID, NULL, false, false, true, false, NULL, 0, NULL, log3, NULL), "eventModeUsed accepted");
    CHECK(!instantiate("x", GUID, NULL, false, false, false, false, NULL, 3, NULL, log3, NULL), "NULL required vars with n=3");
    CHECK(strstr(last_msg, "requiredIntermediateVariables"), "required vars message");
    /* NULL and foreign instances: fmi3Error, nothing to log to, no crash */
    double junk[4] = {0};
    CHECK(get_f64(NULL, &vr, 1, &v, 1) == ERROR, "NULL instance");
    CHECK(get_f64((I)junk, &vr, 1, &v, 1) == ERROR, "foreign instance");
    CHECK(do_step((I)junk, 0, 0.1, false, &b, &b, &b, &d) == ERROR, "foreign instance step3");
    free_instance((I)junk);
    free_instance(NULL);

    I c = instantiate("abuse", GUID, NULL, false, false, false, false, NULL, 0, NULL, log3, NULL);
    CHECK(c, "instantiate");
    EXPECT(step3(c, 0, 0.1), ERROR, "fmi3DoStep"); /* Instantiated */
    EXPECT(exit_init(c), ERROR, "fmi3ExitInitializationMode"); /* now Terminated */
    CHECK(reset(c) == OK, "reset");
    EXPECT(enter_init(c, true, -1.0, 0.0, false, 0.0), ERROR, "fmi3EnterInitializationMode"); /* tolerance */
    CHECK(reset(c) == OK, "reset");
    EXPECT(enter_init(c, false, 0.0, NAN, false, 0.0), ERROR, "fmi3EnterInitializationMode");
    CHECK(reset(c) == OK, "reset");
    EXPECT(enter_init(c, false, 0.0, 1.0, true, 0.5), ERROR, "fmi3EnterInitializationMode"); /* stop < start */
    CHECK(reset(c) == OK, "reset");
    CHECK(enter_init(c, false, 0.0, 0.0, true, 1.0) == OK && exit_init(c) == OK, "init");
    EXPECT(set_f64(c, &in, 1, &nan_, 1), ERROR, "fmi3SetFloat64");
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, true, 1.0) == OK && exit_init(c) == OK, "re-init");
    EXPECT(set_f64(c, &in, 1, NULL, 1), ERROR, "fmi3SetFloat64");
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, true, 1.0) == OK && exit_init(c) == OK, "re-init");
    EXPECT(get_f64(c, NULL, 1, &v, 1), ERROR, "fmi3GetFloat64");
    EXPECT(get_f64(c, &vr, 1, &v, 1), OK, "fmi3GetFloat64"); /* Terminated: values stay readable */
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, true, 1.0) == OK && exit_init(c) == OK, "re-init");
    EXPECT(get_f64(c, &vr, SIZE_MAX, &v, SIZE_MAX), ERROR, "fmi3GetFloat64");
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, true, 1.0) == OK && exit_init(c) == OK, "re-init");
    EXPECT(set_f64(c, &tvr, 1, &v, 1), ERROR, "fmi3SetFloat64");
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, true, 1.0) == OK && exit_init(c) == OK, "re-init");
    EXPECT(step3(c, 0, -0.1), ERROR, "fmi3DoStep");
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, true, 1.0) == OK && exit_init(c) == OK, "re-init");
    EXPECT(step3(c, 0, 2.0), ERROR, "fmi3DoStep"); /* beyond stopTime */
    CHECK(strstr(last_msg, "fmi3EnterInitializationMode"), "stop time message names fmi3EnterInitializationMode");
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, true, 1.0) == OK && exit_init(c) == OK, "re-init");
    EXPECT(do_step(c, 0, 0.1, false, NULL, &b, &b, &d), ERROR, "fmi3DoStep");
    CHECK(reset(c) == OK, "reset");
    /* a bool byte 0xFF for an Int32 variable: refused by type, read without undefined behaviour */
    unsigned mtq = VR_MTQ_ENABLE;
    uint8_t ff = 0xFF;
    EXPECT(set_bool(c, &mtq, 1, &ff, 1), ERROR, "fmi3SetBoolean");
    CHECK(reset(c) == OK, "reset");
    int32_t one = 1;
    EXPECT(set_i32(c, &mtq, 1, &one, 2), ERROR, "fmi3SetInt32"); /* nValues != nValueReferences */
    CHECK(reset(c) == OK, "reset");
    /* FMU states: foreign, freed, corrupted */
    CHECK(enter_init(c, false, 0, 0, false, 0) == OK && exit_init(c) == OK, "init");
    EXPECT(set_state(c, junk), ERROR, "fmi3SetFMUState");
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, false, 0) == OK && exit_init(c) == OK, "re-init");
    void *s = NULL;
    CHECK(get_state(c, &s) == OK, "get state");
    void *freed = s;
    CHECK(free_state(c, &s) == OK, "free state");
    EXPECT(set_state(c, freed), ERROR, "fmi3SetFMUState");
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, false, 0) == OK && exit_init(c) == OK, "re-init");
    uint8_t garbage[64];
    memset(garbage, 0xA5, sizeof garbage);
    void *g = NULL;
    EXPECT(deserialize(c, garbage, sizeof garbage, &g), ERROR, "fmi3DeserializeFMUState");
    CHECK(g == NULL, "no state from garbage");
    EXPECT(deserialize(c, NULL, 10, &g), ERROR, "fmi3DeserializeFMUState");
    /* every refused function: fmi3Error naming itself */
    const char *refused[] = {"fmi3EnterEventMode", "fmi3EnterStepMode", "fmi3EnterConfigurationMode", "fmi3ExitConfigurationMode",
                             "fmi3EvaluateDiscreteStates", "fmi3EnterContinuousTimeMode"};
    for (size_t i = 0; i < sizeof refused / sizeof *refused; i++) {
        St (*f)(I) = sym3(refused[i]);
        CHECK(reset(c) == OK, "reset");
        EXPECT(f(c), ERROR, refused[i]);
    }
    St (*get_f32)(I, const unsigned *, size_t, float *, size_t) = sym3("fmi3GetFloat32");
    float fv;
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, false, 0) == OK, "init");
    EXPECT(get_f32(c, &vr, 1, &fv, 1), ERROR, "fmi3GetFloat32");
    CHECK(!inst_me("me", "{bad}", NULL, false, false, NULL, log3), "Model Exchange instantiated with a bad token");
    CHECK(strstr(last_msg, "fmi3InstantiateModelExchange") && strstr(last_msg, "instantiationToken"), "ME message");
    /* the instance still works after all that */
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, false, 0) == OK && exit_init(c) == OK, "final init");
    CHECK(step3(c, 0, 0.1) == OK, "final step3");
    CHECK(get_f64(c, &tvr, 1, &v, 1) == OK && v == 0.1, "time after a step3");
    free_instance(c);
    free_instance(c); /* double free: ignored */
    printf("ok abuse (%d log messages)\n", n_msgs);
}


/* every Model Exchange entry point given NULL or a foreign instance, then wrong order, lengths, NaN */
static void me_abuse(void) {
    double junk[4] = {0}, x[NX + 1], dx[NX + 1], v, t_next;
    bool b1, b2, b3, b4, b5;
    size_t n;
    I bad[2] = {NULL, (I)junk};
    for (int i = 0; i < 2; i++) {
        I c = bad[i];
        CHECK(enter_ct(c) == ERROR && enter_ev(c) == ERROR && set_time(c, 1.0) == ERROR, "NULL/foreign: mode calls");
        CHECK(update_ds(c, &b1, &b2, &b3, &b4, &b5, &t_next) == ERROR && completed(c, false, &b1, &b2) == ERROR, "NULL/foreign: event calls");
        CHECK(set_x(c, x, NX) == ERROR && get_x(c, x, NX) == ERROR && get_dx(c, dx, NX) == ERROR, "NULL/foreign: state calls");
        CHECK(get_nom(c, x, NX) == ERROR && get_z(c, NULL, 0) == ERROR, "NULL/foreign: nominals, indicators");
        CHECK(n_states(c, &n) == ERROR && n_indicators(c, &n) == ERROR, "NULL/foreign: counts");
    }
    /* instantiation */
    CHECK(!inst_me(NULL, GUID, NULL, false, false, NULL, log3), "ME: NULL name accepted");
    CHECK(strstr(last_msg, "fmi3InstantiateModelExchange") && strstr(last_msg, "instanceName"), "ME: NULL name message");
    CHECK(!inst_me("", GUID, NULL, false, false, NULL, log3), "ME: empty name accepted");
    CHECK(!inst_me("x", NULL, NULL, false, false, NULL, log3), "ME: NULL token accepted");
    CHECK(strstr(last_msg, "instantiationToken is NULL"), "ME: NULL token message");
    CHECK(!inst_me("x", "{bad}", NULL, false, false, NULL, NULL), "ME: bad token without logger");
    I quiet = inst_me("quiet", GUID, NULL, false, false, NULL, NULL); /* no logger: fine, errors go nowhere */
    CHECK(quiet && set_time(quiet, 1.0) == ERROR, "ME without logger");
    free_instance(quiet);

    I c = inst_me("meabuse", GUID, NULL, false, false, NULL, log3);
    CHECK(c, "fmi3InstantiateModelExchange");
    EXPECT(n_states(c, &n), OK, "fmi3GetNumberOfContinuousStates");
    CHECK(n == NX, "18 continuous states");
    EXPECT(n_indicators(c, &n), OK, "fmi3GetNumberOfEventIndicators");
    CHECK(n == 0, "no event indicators");
    EXPECT(n_states(c, NULL), ERROR, "fmi3GetNumberOfContinuousStates");
#define RESET_INIT() CHECK(reset(c) == OK && enter_init(c, false, 0, 0, false, 0) == OK && exit_init(c) == OK, "re-init")
#define RESET_CT() do { RESET_INIT(); CHECK(update(c) == OK && enter_ct(c) == OK, "to continuous time"); } while (0)
    /* wrong order: Instantiated */
    CHECK(reset(c) == OK, "reset");
    EXPECT(set_time(c, 0.0), ERROR, "fmi3SetTime");
    CHECK(strstr(last_msg, "Instantiated"), "state named");
    CHECK(reset(c) == OK, "reset");
    EXPECT(get_x(c, x, NX), ERROR, "fmi3GetContinuousStates");
    CHECK(reset(c) == OK, "reset");
    EXPECT(update(c), ERROR, "fmi3UpdateDiscreteStates");
    CHECK(reset(c) == OK, "reset");
    EXPECT(enter_ct(c), ERROR, "fmi3EnterContinuousTimeMode");
    /* wrong order: Event Mode */
    RESET_INIT();
    EXPECT(set_x(c, x, NX), ERROR, "fmi3SetContinuousStates");
    CHECK(strstr(last_msg, "Event Mode"), "state named");
    RESET_INIT();
    EXPECT(completed(c, false, &b1, &b2), ERROR, "fmi3CompletedIntegratorStep");
    RESET_INIT();
    EXPECT(enter_ev(c), ERROR, "fmi3EnterEventMode");
    RESET_INIT();
    EXPECT(step3(c, 0, 0.1), ERROR, "fmi3DoStep");
    CHECK(strstr(last_msg, "fmi3InstantiateModelExchange"), "DoStep on ME says why");
    /* NULL out-pointers of the event iteration, one at a time */
    for (int k = 0; k < 6; k++) {
        bool bb[5];
        double tt;
        bool *p[5] = {&bb[0], &bb[1], &bb[2], &bb[3], &bb[4]};
        if (k < 5) p[k] = NULL;
        RESET_INIT();
        EXPECT(update_ds(c, p[0], p[1], p[2], p[3], p[4], k == 5 ? NULL : &tt), ERROR, "fmi3UpdateDiscreteStates");
    }
    /* wrong order: Continuous-Time Mode */
    RESET_CT();
    EXPECT(update(c), ERROR, "fmi3UpdateDiscreteStates");
    RESET_CT();
    EXPECT(enter_ct(c), ERROR, "fmi3EnterContinuousTimeMode");
    RESET_CT();
    EXPECT(exit_init(c), ERROR, "fmi3ExitInitializationMode");
    /* lengths, NULL arrays */
    size_t lens[3] = {NX - 1, NX + 1, SIZE_MAX};
    for (int i = 0; i < 3; i++) {
        RESET_CT();
        EXPECT(get_x(c, x, lens[i]), ERROR, "fmi3GetContinuousStates");
        RESET_CT();
        EXPECT(set_x(c, x, lens[i]), ERROR, "fmi3SetContinuousStates");
        RESET_CT();
        EXPECT(get_dx(c, dx, lens[i]), ERROR, "fmi3GetContinuousStateDerivatives");
        RESET_CT();
        EXPECT(get_nom(c, dx, lens[i]), ERROR, "fmi3GetNominalsOfContinuousStates");
    }
    RESET_CT();
    EXPECT(get_x(c, NULL, NX), ERROR, "fmi3GetContinuousStates");
    RESET_CT();
    EXPECT(set_x(c, NULL, NX), ERROR, "fmi3SetContinuousStates");
    RESET_CT();
    EXPECT(get_dx(c, NULL, NX), ERROR, "fmi3GetContinuousStateDerivatives");
    RESET_CT();
    EXPECT(get_z(c, x, 1), ERROR, "fmi3GetEventIndicators");
    RESET_CT();
    EXPECT(get_z(c, NULL, 0), OK, "fmi3GetEventIndicators");
    EXPECT(completed(c, false, NULL, &b2), ERROR, "fmi3CompletedIntegratorStep");
    RESET_CT();
    EXPECT(completed(c, false, &b1, NULL), ERROR, "fmi3CompletedIntegratorStep");
    /* non-finite states and times */
    RESET_CT();
    CHECK(get_x(c, x, NX) == OK, "get x");
    x[3] = NAN;
    EXPECT(set_x(c, x, NX), ERROR, "fmi3SetContinuousStates");
    CHECK(strstr(last_msg, "state_att_4"), "NaN state named");
    RESET_CT();
    CHECK(get_x(c, x, NX) == OK, "get x");
    x[K_W_X] = INFINITY;
    EXPECT(set_x(c, x, NX), ERROR, "fmi3SetContinuousStates");
    double times[3] = {NAN, INFINITY, -INFINITY};
    for (int i = 0; i < 3; i++) {
        RESET_CT();
        EXPECT(set_time(c, times[i]), ERROR, "fmi3SetTime");
    }
    RESET_CT();
    EXPECT(set_time(c, -5.0), ERROR, "fmi3SetTime"); /* before the last event (initialization at 0) */
    RESET_CT();
    unsigned svr = VR_STATE0 + K_W_X, dvr = VR_DER0 + K_W_X, ivr = VR_INERTIA_XX, mtq = VR_MTQ_ENABLE;
    double nan_ = NAN, one = 1.0;
    EXPECT(set_f64(c, &svr, 1, &nan_, 1), ERROR, "fmi3SetFloat64");
    RESET_CT();
    EXPECT(set_f64(c, &dvr, 1, &one, 1), ERROR, "fmi3SetFloat64");
    RESET_CT();
    EXPECT(set_f64(c, &ivr, 1, &one, 1), ERROR, "fmi3SetFloat64"); /* a parameter in Continuous-Time Mode */
    RESET_CT();
    int32_t i1 = 1;
    EXPECT(set_i32(c, &mtq, 1, &i1, 1), ERROR, "fmi3SetInt32");
    /* FMU states across the interfaces */
    RESET_CT();
    void *me_state = NULL, *cs_state = NULL;
    CHECK(get_state(c, &me_state) == OK && me_state, "ME state");
    I cs = ready3();
    EXPECT(set_state(cs, me_state), ERROR, "fmi3SetFMUState");
    CHECK(strstr(last_msg, "Model Exchange"), "ME state into CS says why");
    CHECK(reset(cs) == OK && enter_init(cs, false, 0, 0, false, 0) == OK && exit_init(cs) == OK, "CS re-init");
    CHECK(get_state(cs, &cs_state) == OK && cs_state, "CS state");
    EXPECT(set_state(c, cs_state), ERROR, "fmi3SetFMUState");
    CHECK(free_state(cs, &cs_state) == OK, "free CS state");
    EXPECT(get_x(cs, x, NX), ERROR, "fmi3GetContinuousStates"); /* ME call on a CS instance */
    CHECK(strstr(last_msg, "fmi3InstantiateCoSimulation"), "ME call on CS says why");
    free_instance(cs);
    /* the ME state restores, serialized and back */
    RESET_CT();
    CHECK(set_state(c, me_state) == OK, "ME state into the ME instance");
    size_t sz = 0;
    CHECK(ser_size(c, me_state, &sz) == OK && sz > 0, "ME serialized size");
    uint8_t *buf = malloc(sz);
    void *back = NULL;
    CHECK(serialize3(c, me_state, buf, sz) == OK && deserialize(c, buf, sz, &back) == OK && set_state(c, back) == OK, "ME serialize3 round trip");
    buf[sz / 2] ^= 0x5A;
    void *g = NULL;
    EXPECT(deserialize(c, buf, sz, &g), ERROR, "fmi3DeserializeFMUState");
    free(buf);
    CHECK(free_state(c, &back) == OK && free_state(c, &me_state) == OK, "free ME states");
    /* after all that: an explicit Euler run under torque about the principal axis x from rest,
     * w_x' = tau / I_xx exactly, so Euler is exact up to rounding */
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, false, 0) == OK, "final init");
    unsigned tq = VR_TORQUE_CMD_X;
    double tau = 0.4, h = 0.01;
    CHECK(set_f64(c, &tq, 1, &tau, 1) == OK && exit_init(c) == OK && update(c) == OK && enter_ct(c) == OK, "final to CT");
    CHECK(get_x(c, x, NX) == OK, "final x");
    double t = 0;
    for (int k = 0; k < 100; k++) {
        CHECK(get_dx(c, dx, NX) == OK, "final dx");
        CHECK(fabs(dx[K_W_X] - tau / 1000.0) < 1e-15, "w_x' = tau / I_xx");
        for (int i = 0; i < NX; i++) x[i] += h * dx[i];
        t = (k + 1) * h;
        CHECK(set_time(c, t) == OK && set_x(c, x, NX) == OK, "final set");
        CHECK(completed(c, true, &b1, &b2) == OK && !b2, "completed step3");
        if (b1) CHECK(enter_ev(c) == OK && update(c) == OK && enter_ct(c) == OK && get_x(c, x, NX) == OK, "projection event");
    }
    unsigned wx = VR_W_X;
    CHECK(get_f64(c, &wx, 1, &v, 1) == OK && fabs(v - tau / 1000.0 * t) < 1e-14, "w_x = tau t / I_xx after Euler");
    CHECK(terminate_(c) == OK, "ME terminate");
    EXPECT(set_time(c, t), ERROR, "fmi3SetTime"); /* Terminated */
    CHECK(get_x(c, x, NX) == OK, "states readable in Terminated");
    free_instance(c);
    CHECK(set_time(c, t) == ERROR, "freed ME instance accepted"); /* a foreign pointer now: no crash, nothing to log to */
    free_instance(c);
    printf("ok me (%d log messages) w_x=%.17g\n", n_msgs, v);
}

static void mixed(void) {
    typedef struct { void (*logger)(void *, const char *, int, const char *, const char *, ...); void *a, *f, *s, *env; } Cb2;
    I (*inst2)(const char *, int, const char *, const char *, const Cb2 *, int, int) = sym3("fmi2Instantiate");
    St (*setup2)(I, int, double, double, int, double) = sym3("fmi2SetupExperiment");
    St (*enter2)(I) = sym3("fmi2EnterInitializationMode");
    St (*exit2)(I) = sym3("fmi2ExitInitializationMode");
    St (*set2)(I, const unsigned *, size_t, const double *) = sym3("fmi2SetReal");
    St (*get2)(I, const unsigned *, size_t, double *) = sym3("fmi2GetReal");
    St (*step2)(I, double, double, int) = sym3("fmi2DoStep");
    void (*free2)(I) = sym3("fmi2FreeInstance");
    static const Cb2 cb = {NULL, NULL, NULL, NULL, NULL};
    I a = inst2("two", 1, GUID, NULL, &cb, 0, 0);
    CHECK(a, "fmi2Instantiate");
    I c = ready3();
    unsigned ivr = VR_INIT_W_X, tq = VR_TORQUE_CMD_X, out = VR_W_X;
    double w0 = 0.05, u = 0.25, w2, w3;
    CHECK(set2(a, &ivr, 1, &w0) == OK && setup2(a, 0, 0, 0, 1, 100.0) == OK && enter2(a) == OK && exit2(a) == OK, "fmi2 init");
    /* neither API accepts the other's instance */
    CHECK(get_f64(a, &out, 1, &w2, 1) == ERROR, "fmi3 call accepted an FMI 2.0 instance");
    CHECK(get2(c, &out, 1, &w3) == ERROR, "fmi2 call accepted an FMI 3.0 instance");
    free2(c);           /* ignored: not an FMI 2.0 instance */
    free_instance(a);   /* ignored: not an FMI 3.0 instance */
    double t = 0;
    for (int k = 0; k < 50; k++, t += 0.05) {
        CHECK(set2(a, &tq, 1, &u) == OK && set_f64(c, &tq, 1, &u, 1) == OK, "set torque");
        CHECK(step2(a, t, 0.05, 1) == OK && step3(c, t, 0.05) == OK, "step3 both");
        CHECK(get2(a, &out, 1, &w2) == OK && get_f64(c, &out, 1, &w3, 1) == OK, "get both");
        CHECK(memcmp(&w2, &w3, sizeof w2) == 0, "FMI 2.0 and FMI 3.0 instances differ");
    }
    /* an FMU state belongs to the FMI version of the instance that took it (issue 45) */
    St (*get_state2)(I, void **) = sym3("fmi2GetFMUstate");
    St (*set_state2)(I, void *) = sym3("fmi2SetFMUstate");
    St (*free_state2)(I, void **) = sym3("fmi2FreeFMUstate");
    void *s2 = NULL, *s3 = NULL;
    CHECK(get_state2(a, &s2) == OK && get_state(c, &s3) == OK, "get an FMU state through each version");
    CHECK(set_state2(a, s3) == ERROR, "fmi2SetFMUstate accepted a state taken through FMI 3.0");
    EXPECT(set_state(c, s2), ERROR, "fmi3SetFMUState");
    CHECK(strstr(last_msg, "taken by an FMI 2.0 instance"), "fmi3SetFMUState: message does not name the version");
    CHECK(set_state2(a, s2) == OK && set_state(c, s3) == OK, "a state restored through its own version");
    CHECK(free_state2(a, &s2) == OK && free_state(c, &s3) == OK, "free states");
    free2(a);
    free_instance(c);
    printf("ok mixed w_x=%.17g (FMU states refused across versions)\n", w3);
}

static void epoch3(double h) {
    for (int i = 0; i < N_EPOCHS; i++) {
        double t0 = EPOCHS[i];
        I c = instantiate("epoch3", GUID, NULL, false, false, false, false, NULL, 0, NULL, log3, NULL);
        CHECK(c, "fmi3InstantiateCoSimulation");
        if (TIMED("fmi3EnterInitializationMode", t0, enter_init(c, false, 0.0, t0, false, 0.0)) == OK &&
            TIMED("fmi3ExitInitializationMode", t0, exit_init(c)) == OK) {
            bool ev, term, early;
            double last;
            if (TIMED("fmi3DoStep", t0, do_step(c, t0, h, false, &ev, &term, &early, &last)) == OK)
                TIMED("fmi3DoStep", t0, do_step(c, t0 + h, h, false, &ev, &term, &early, &last));
        }
        free_instance(c);
    }
}

/* reuse mode (FMI 3.0), as reuse_round2: stale instance handles first (b must then run on to the reference),
   then the stale states given to b (each fmi3Error puts b into Terminated, where its outputs stay readable) */
static StalePool pool3 = {.lock = PTHREAD_MUTEX_INITIALIZER};
typedef struct {
    int n, same_addr, same_state;
    long refused;
    double ref;
    I first_c, c[STALE_KEEP];
    void *first_s, *s[2 * STALE_KEEP];
    unsigned nc, ns;
} Reuse3;

static void stale_refused3(St got, const char *call, const char *fn, long *refused) {
    if (got == ERROR && (!fn || strstr(last_msg, fn))) { (*refused)++; return; }
    printf("FAIL %s with a stale handle returned %d (expected fmi3Error%s%s; last message: %s)\n", call, got,
           fn ? " and a message naming " : "", fn ? fn : "", last_msg);
    fflush(stdout);
    exit(1);
}

static void stale_instance3(I stale, long *refused) {
    unsigned in = VR_TORQUE_CMD_X, out = VR_W_X;
    double u = 1e3, w, last;
    bool ev, term, early;
    void *sx = NULL;
    stale_refused3(do_step(stale, 0.5, 0.1, false, &ev, &term, &early, &last), "fmi3DoStep", NULL, refused);
    stale_refused3(set_f64(stale, &in, 1, &u, 1), "fmi3SetFloat64", NULL, refused);
    stale_refused3(get_f64(stale, &out, 1, &w, 1), "fmi3GetFloat64", NULL, refused);
    stale_refused3(get_state(stale, &sx), "fmi3GetFMUState", NULL, refused);
    stale_refused3(reset(stale), "fmi3Reset", NULL, refused);
    free_instance(stale); /* must be ignored */
}

static void stale_state3(I b, void *s, long *refused) {
    size_t n;
    void *copy = s;
    stale_refused3(set_state(b, s), "fmi3SetFMUState", "fmi3SetFMUState", refused);
    stale_refused3(ser_size(b, s, &n), "fmi3SerializedFMUStateSize", "fmi3SerializedFMUStateSize", refused);
    stale_refused3(free_state(b, &copy), "fmi3FreeFMUState", "fmi3FreeFMUState", refused);
}

static double w_x3(I c) {
    unsigned out = VR_W_X;
    double w = NAN;
    CHECK(get_f64(c, &out, 1, &w, 1) == OK, "get w_x");
    return w;
}

/* init_w_x 0.05, torque 0.5, n steps of 0.1 from *t */
static void run3(I c, double *t, int n) {
    unsigned vr = VR_TORQUE_CMD_X;
    double tq = 0.5;
    CHECK(set_f64(c, &vr, 1, &tq, 1) == OK, "set torque");
    for (int k = 0; k < n; k++, *t += 0.1) CHECK(step3(c, *t, 0.1) == OK, "step3");
}

static void reuse_round3(Reuse3 *r) {
    I a = ready3();
    double t = 0;
    run3(a, &t, 3);
    void *s1 = NULL, *s2 = NULL;
    CHECK(get_state(a, &s1) == OK && get_state(a, &s2) == OK, "get states of a");
    void *s2_stale = s2;
    CHECK(free_state(a, &s2) == OK && !s2, "free state s2");
    free_instance(a); /* frees s1 with it */
    I b = ready3();
    void *sb = NULL;
    CHECK(get_state(b, &sb) == OK, "get state of b");
    r->same_addr += b == a;
    r->same_state += sb == s1 || sb == s2_stale;
    t = 0;
    run3(b, &t, 5);
    double w = w_x3(b);
    if (!r->first_c) { r->first_c = a; r->first_s = s1; }
    r->c[r->nc++ % STALE_KEEP] = a;
    r->s[r->ns++ % (2 * STALE_KEEP)] = s1;
    r->s[r->ns++ % (2 * STALE_KEEP)] = s2_stale;
    pthread_mutex_lock(&pool3.lock);
    pool3.c[pool3.nc++ % STALE_POOL] = a;
    pool3.s[pool3.ns++ % (2 * STALE_POOL)] = s1;
    I shared_c[8];
    void *shared_s[8];
    int k_shared = pool3.nc < 8 ? (int)pool3.nc : 8;
    for (int k = 0; k < k_shared; k++) {
        shared_c[k] = pool3.c[(unsigned)next() % (pool3.nc < STALE_POOL ? pool3.nc : STALE_POOL)];
        shared_s[k] = pool3.s[(unsigned)next() % (pool3.ns < 2 * STALE_POOL ? pool3.ns : 2 * STALE_POOL)];
    }
    pthread_mutex_unlock(&pool3.lock);
    stale_instance3(r->first_c, &r->refused);
    for (unsigned k = 0; k < r->nc && k < STALE_KEEP; k++) stale_instance3(r->c[k], &r->refused);
    for (int k = 0; k < k_shared; k++) stale_instance3(shared_c[k], &r->refused);
    CHECK(w_x3(b) == w, "a stale handle changed the new instance's output");
    run3(b, &t, 5);
    double w_end = w_x3(b);
    CHECK(w_end == r->ref, "the new instance's run differs from a fresh one");
    stale_state3(b, r->first_s, &r->refused);
    for (unsigned k = 0; k < r->ns && k < 2 * STALE_KEEP; k++) stale_state3(b, r->s[k], &r->refused);
    for (int k = 0; k < k_shared; k++) stale_state3(b, shared_s[k], &r->refused);
    CHECK(w_x3(b) == w_end, "a stale FMU state changed the new instance");
    CHECK(free_state(b, &sb) == OK, "free state of b");
    free_instance(b);
}

static void *reuse_worker3(void *arg) {
    Reuse3 *r = (Reuse3 *)arg;
    for (int i = 0; i < r->n; i++) reuse_round3(r);
    return NULL;
}

static void reuse3(int n, int nt, int hold) {
    CHECK(nt > 0 && nt <= 64 && hold >= 0, "1 to 64 threads, HOLD >= 0");
    I *held = malloc(sizeof(I) * (size_t)(hold + 1));
    for (int i = 0; i < hold; i++) held[i] = ready3();
    I c = ready3();
    double t = 0;
    run3(c, &t, 10);
    double ref = w_x3(c);
    free_instance(c);
    rng = 20261129;
    static Reuse3 r[64];
    pthread_t th[64];
    for (int i = 0; i < nt; i++) {
        r[i] = (Reuse3){.n = n, .ref = ref};
        CHECK(pthread_create(&th[i], NULL, reuse_worker3, &r[i]) == 0, "pthread_create");
    }
    long refused = 0;
    int same_addr = 0, same_state = 0;
    for (int i = 0; i < nt; i++) {
        pthread_join(th[i], NULL);
        refused += r[i].refused;
        same_addr += r[i].same_addr;
        same_state += r[i].same_state;
    }
    for (int i = 0; i < hold; i++) {
        CHECK(w_x3(held[i]) == 0.05, "a held instance changed");
        free_instance(held[i]);
    }
    free(held);
    printf("ok reuse %d threads x %d rounds (%d other instances held): %ld stale calls refused; the new instance had "
           "the freed one's handle value in %d rounds, its state a freed state's in %d\n", nt, n, hold, refused,
           same_addr, same_state);
}

static int main3(int argc, char **argv) {
    if (argc < 4) { fprintf(stderr, "usage: %s LIB GUID MODE [ARGS]\n", argv[0]); return 2; }
    LIB = argv[1];
    GUID = argv[2];
    const char *mode = argv[3];
    load3();
    load_me();
    if (!strcmp(mode, "cycles")) {
        int n = argc > 4 ? atoi(argv[4]) : 100;
        double ref = cycle3();
        for (int i = 1; i < n; i++) {
            double w = cycle3();
            CHECK(memcmp(&w, &ref, sizeof w) == 0, "cycle3 gave different bits");
        }
        printf("ok cycles %d w_x=%.17g\n", n, ref);
    } else if (!strcmp(mode, "epoch")) {
        epoch3(argc > 4 ? atof(argv[4]) : 0.1);
        printf("ok epoch: %d calls returned within 1 s, %d refused with Error naming the function (%d naming the 2^53 bound)\n",
               n_epoch_calls, n_epoch_refused, n_epoch_bound);
    } else if (!strcmp(mode, "abuse")) {
        abuse();
    } else if (!strcmp(mode, "mixed")) {
        mixed();
    } else if (!strcmp(mode, "reuse")) {
        reuse3(atoi(argv[4]), argc > 5 ? atoi(argv[5]) : 1, argc > 6 ? atoi(argv[6]) : 0);
    } else if (!strcmp(mode, "me")) {
        me_abuse();
    } else {
        fprintf(stderr, "unknown mode %s\n", mode);
        return 2;
    }
    dlclose(lib3);
    return 0;
}

int main(int argc, char **argv) {
    if (argc > 1 && !strcmp(argv[1], "-3")) {
        argv[1] = argv[0];
        return main3(argc - 1, argv + 1);
    }
    return main2(argc, argv);
}
