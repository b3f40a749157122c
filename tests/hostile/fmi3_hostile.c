/* A hostile FMI 3.0 master in C: loads an FMU binary with dlopen and drives its fmi3* functions the way a
 * careless or malicious tool would. Each mode prints one summary line "ok ..." and exits 0, or prints what
 * went wrong and exits 1. Run under valgrind / a timeout by tests/test_hardening.py.
 *
 *   fmi3_hostile LIB TOKEN cycles N   instantiate/init/step/state/serialize/deserialize/free N times:
 *                                     every cycle gives the same bits
 *   fmi3_hostile LIB TOKEN abuse      NULL and foreign pointers, wrong states, NaN, bool bytes other than
 *                                     0/1, wrong counts, every refused function: the prescribed status,
 *                                     a log message naming the function, and the instance recovers
 *   fmi3_hostile LIB TOKEN mixed      an FMI 2.0 and an FMI 3.0 instance of the same library side by side
 *                                     give identical results; neither API accepts the other's instance
 *   fmi3_hostile LIB TOKEN me         Model Exchange: NULL and foreign pointers on every ME entry point,
 *                                     wrong call order, wrong lengths, NaN states and times, Co-Simulation
 *                                     calls on an ME instance and FMU states across the two; then an
 *                                     explicit Euler run whose rate matches the closed form w_x = tau t / I_xx
 *
 * LIB must be an AttitudePlant binary (value references from modelDescription/fmi3/AttitudePlant.xml).
 */
#include <dlfcn.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void *I;
typedef int St;
enum { OK = 0, WARNING = 1, DISCARD = 2, ERROR = 3, FATAL = 4 };
enum { VR_TORQUE_CMD_X = 0, VR_W_X = 14, VR_INIT_W_X = 113, VR_MTQ_ENABLE = 144, VR_INERTIA_XX = 100 };
/* Model Exchange (modelDescription/fmi3/AttitudePlant.xml): 18 states, state k at 1000000000 + k, its
 * derivative at 1000100000 + k; state 9 is state_w_x */
enum { NX = 18, K_W_X = 9 };
static const unsigned VR_STATE0 = 1000000000u, VR_DER0 = 1000100000u;
static const unsigned TIME_VR = 2147483647u;

typedef void (*Log3)(void *, int, const char *, const char *);
typedef I (*Inst3)(const char *, const char *, const char *, bool, bool, bool, bool, const unsigned *, size_t, void *, Log3, void *);

static const char *LIB, *TOKEN;
static char last_msg[2048];
static int n_msgs;

static void log3(void *env, int status, const char *cat, const char *msg) {
    (void)env; (void)cat;
    if (getenv("HOSTILE_VERBOSE")) fprintf(stderr, "[%d] %s\n", status, msg);
    snprintf(last_msg, sizeof last_msg, "%s", msg);
    n_msgs++;
}

static void die(const char *what) { printf("FAIL %s (last message: %s)\n", what, last_msg); fflush(stdout); exit(1); }
#define CHECK(cond, what) do { if (!(cond)) die(what); } while (0)
/* status st and a fresh log message containing func */
#define EXPECT(call, st, func) do { last_msg[0] = 0; St r_ = (call); \
    if (r_ != (st)) { char b_[256]; snprintf(b_, sizeof b_, "%s returned %d, expected %d", func, r_, st); die(b_); } \
    if ((st) >= ERROR && !strstr(last_msg, func)) { char b_[256]; snprintf(b_, sizeof b_, "%s logged no message naming it", func); die(b_); } } while (0)

static void *lib;
static void *sym(const char *name) {
    void *p = dlsym(lib, name);
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
static St (*serialize)(I, void *, uint8_t *, size_t);
static St (*deserialize)(I, const uint8_t *, size_t, void **);

static void load(void) {
    lib = dlopen(LIB, RTLD_NOW | RTLD_LOCAL);
    if (!lib) { printf("FAIL dlopen %s: %s\n", LIB, dlerror()); exit(1); }
    instantiate = (Inst3)sym("fmi3InstantiateCoSimulation");
    free_instance = sym("fmi3FreeInstance");
    enter_init = sym("fmi3EnterInitializationMode");
    exit_init = sym("fmi3ExitInitializationMode");
    terminate_ = sym("fmi3Terminate");
    reset = sym("fmi3Reset");
    get_f64 = sym("fmi3GetFloat64");
    set_f64 = sym("fmi3SetFloat64");
    set_bool = sym("fmi3SetBoolean");
    set_i32 = sym("fmi3SetInt32");
    do_step = sym("fmi3DoStep");
    get_state = sym("fmi3GetFMUState");
    set_state = sym("fmi3SetFMUState");
    free_state = sym("fmi3FreeFMUState");
    ser_size = sym("fmi3SerializedFMUStateSize");
    serialize = sym("fmi3SerializeFMUState");
    deserialize = sym("fmi3DeserializeFMUState");
}

static I ready(void) {
    I c = instantiate("hostile3", TOKEN, NULL, false, false, false, false, NULL, 0, NULL, log3, NULL);
    CHECK(c, "fmi3InstantiateCoSimulation");
    unsigned vr = VR_INIT_W_X;
    double v = 0.05;
    CHECK(set_f64(c, &vr, 1, &v, 1) == OK, "set init_w_x");
    CHECK(enter_init(c, false, 0.0, 0.0, true, 100.0) == OK, "enter init");
    CHECK(exit_init(c) == OK, "exit init");
    return c;
}

static St step(I c, double t, double h) {
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
    inst_me = (InstMe)sym("fmi3InstantiateModelExchange");
    enter_ct = sym("fmi3EnterContinuousTimeMode");
    enter_ev = sym("fmi3EnterEventMode");
    update_ds = sym("fmi3UpdateDiscreteStates");
    completed = sym("fmi3CompletedIntegratorStep");
    set_time = sym("fmi3SetTime");
    set_x = sym("fmi3SetContinuousStates");
    get_x = sym("fmi3GetContinuousStates");
    get_dx = sym("fmi3GetContinuousStateDerivatives");
    get_nom = sym("fmi3GetNominalsOfContinuousStates");
    get_z = sym("fmi3GetEventIndicators");
    n_states = sym("fmi3GetNumberOfContinuousStates");
    n_indicators = sym("fmi3GetNumberOfEventIndicators");
}

static St update(I c) {
    bool need = true, term = true, nom = true, val = true, def = true;
    double next = -1;
    return update_ds(c, &need, &term, &nom, &val, &def, &next);
}

/* an ME instance in Continuous-Time Mode with init_w_x = 0.05 */
static I ready_me(void) {
    I c = inst_me("hostile3me", TOKEN, NULL, false, false, NULL, log3);
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

static double cycle(void) {
    I c = ready();
    unsigned vr = VR_TORQUE_CMD_X, out = VR_W_X;
    double tq = 0.5, w1, w2, t = 0;
    CHECK(set_f64(c, &vr, 1, &tq, 1) == OK, "set torque");
    for (int k = 0; k < 10; k++, t += 0.1) CHECK(step(c, t, 0.1) == OK, "step");
    void *s = NULL;
    CHECK(get_state(c, &s) == OK && s, "get state");
    size_t n = 0;
    CHECK(ser_size(c, s, &n) == OK && n > 0, "serialized size");
    uint8_t *buf = malloc(n);
    CHECK(serialize(c, s, buf, n) == OK, "serialize");
    CHECK(step(c, t, 0.1) == OK, "step after state");
    CHECK(get_f64(c, &out, 1, &w1, 1) == OK, "get w_x");
    void *d = NULL;
    CHECK(deserialize(c, buf, n, &d) == OK && d, "deserialize");
    CHECK(set_state(c, d) == OK, "set state");
    CHECK(step(c, t, 0.1) == OK, "step after restore");
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
    CHECK(!instantiate(NULL, TOKEN, NULL, false, false, false, false, NULL, 0, NULL, log3, NULL), "NULL name accepted");
    CHECK(strstr(last_msg, "fmi3InstantiateCoSimulation") && strstr(last_msg, "instanceName"), "NULL name message");
    CHECK(!instantiate("x", NULL, NULL, false, false, false, false, NULL, 0, NULL, log3, NULL), "NULL token accepted");
    CHECK(!instantiate("x", "{bad}", NULL, false, false, false, false, NULL, 0, NULL, NULL, NULL), "bad token without logger");
    CHECK(!instantiate("x", TOKEN, NULL, false, false, true, false, NULL, 0, NULL, log3, NULL), "eventModeUsed accepted");
    CHECK(!instantiate("x", TOKEN, NULL, false, false, false, false, NULL, 3, NULL, log3, NULL), "NULL required vars with n=3");
    CHECK(strstr(last_msg, "requiredIntermediateVariables"), "required vars message");
    /* NULL and foreign instances: fmi3Error, nothing to log to, no crash */
    double junk[4] = {0};
    CHECK(get_f64(NULL, &vr, 1, &v, 1) == ERROR, "NULL instance");
    CHECK(get_f64((I)junk, &vr, 1, &v, 1) == ERROR, "foreign instance");
    CHECK(do_step((I)junk, 0, 0.1, false, &b, &b, &b, &d) == ERROR, "foreign instance step");
    free_instance((I)junk);
    free_instance(NULL);

    I c = instantiate("abuse", TOKEN, NULL, false, false, false, false, NULL, 0, NULL, log3, NULL);
    CHECK(c, "instantiate");
    EXPECT(step(c, 0, 0.1), ERROR, "fmi3DoStep"); /* Instantiated */
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
    EXPECT(step(c, 0, -0.1), ERROR, "fmi3DoStep");
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, true, 1.0) == OK && exit_init(c) == OK, "re-init");
    EXPECT(step(c, 0, 2.0), ERROR, "fmi3DoStep"); /* beyond stopTime */
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
        St (*f)(I) = sym(refused[i]);
        CHECK(reset(c) == OK, "reset");
        EXPECT(f(c), ERROR, refused[i]);
    }
    St (*get_f32)(I, const unsigned *, size_t, float *, size_t) = sym("fmi3GetFloat32");
    float fv;
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, false, 0) == OK, "init");
    EXPECT(get_f32(c, &vr, 1, &fv, 1), ERROR, "fmi3GetFloat32");
    CHECK(!inst_me("me", "{bad}", NULL, false, false, NULL, log3), "Model Exchange instantiated with a bad token");
    CHECK(strstr(last_msg, "fmi3InstantiateModelExchange") && strstr(last_msg, "instantiationToken"), "ME message");
    /* the instance still works after all that */
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, false, 0) == OK && exit_init(c) == OK, "final init");
    CHECK(step(c, 0, 0.1) == OK, "final step");
    CHECK(get_f64(c, &tvr, 1, &v, 1) == OK && v == 0.1, "time after a step");
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
    CHECK(!inst_me(NULL, TOKEN, NULL, false, false, NULL, log3), "ME: NULL name accepted");
    CHECK(strstr(last_msg, "fmi3InstantiateModelExchange") && strstr(last_msg, "instanceName"), "ME: NULL name message");
    CHECK(!inst_me("", TOKEN, NULL, false, false, NULL, log3), "ME: empty name accepted");
    CHECK(!inst_me("x", NULL, NULL, false, false, NULL, log3), "ME: NULL token accepted");
    CHECK(strstr(last_msg, "instantiationToken is NULL"), "ME: NULL token message");
    CHECK(!inst_me("x", "{bad}", NULL, false, false, NULL, NULL), "ME: bad token without logger");
    I quiet = inst_me("quiet", TOKEN, NULL, false, false, NULL, NULL); /* no logger: fine, errors go nowhere */
    CHECK(quiet && set_time(quiet, 1.0) == ERROR, "ME without logger");
    free_instance(quiet);

    I c = inst_me("meabuse", TOKEN, NULL, false, false, NULL, log3);
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
    EXPECT(step(c, 0, 0.1), ERROR, "fmi3DoStep");
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
    I cs = ready();
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
    CHECK(serialize(c, me_state, buf, sz) == OK && deserialize(c, buf, sz, &back) == OK && set_state(c, back) == OK, "ME serialize round trip");
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
        CHECK(completed(c, true, &b1, &b2) == OK && !b2, "completed step");
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
    I (*inst2)(const char *, int, const char *, const char *, const Cb2 *, int, int) = sym("fmi2Instantiate");
    St (*setup2)(I, int, double, double, int, double) = sym("fmi2SetupExperiment");
    St (*enter2)(I) = sym("fmi2EnterInitializationMode");
    St (*exit2)(I) = sym("fmi2ExitInitializationMode");
    St (*set2)(I, const unsigned *, size_t, const double *) = sym("fmi2SetReal");
    St (*get2)(I, const unsigned *, size_t, double *) = sym("fmi2GetReal");
    St (*step2)(I, double, double, int) = sym("fmi2DoStep");
    void (*free2)(I) = sym("fmi2FreeInstance");
    static const Cb2 cb = {NULL, NULL, NULL, NULL, NULL};
    I a = inst2("two", 1, TOKEN, NULL, &cb, 0, 0);
    CHECK(a, "fmi2Instantiate");
    I c = ready();
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
        CHECK(step2(a, t, 0.05, 1) == OK && step(c, t, 0.05) == OK, "step both");
        CHECK(get2(a, &out, 1, &w2) == OK && get_f64(c, &out, 1, &w3, 1) == OK, "get both");
        CHECK(memcmp(&w2, &w3, sizeof w2) == 0, "FMI 2.0 and FMI 3.0 instances differ");
    }
    free2(a);
    free_instance(c);
    printf("ok mixed w_x=%.17g\n", w3);
}

int main(int argc, char **argv) {
    if (argc < 4) { fprintf(stderr, "usage: %s LIB TOKEN MODE [ARGS]\n", argv[0]); return 2; }
    LIB = argv[1];
    TOKEN = argv[2];
    const char *mode = argv[3];
    load();
    load_me();
    if (!strcmp(mode, "cycles")) {
        int n = argc > 4 ? atoi(argv[4]) : 100;
        double ref = cycle();
        for (int i = 1; i < n; i++) {
            double w = cycle();
            CHECK(memcmp(&w, &ref, sizeof w) == 0, "cycle gave different bits");
        }
        printf("ok cycles %d w_x=%.17g\n", n, ref);
    } else if (!strcmp(mode, "abuse")) {
        abuse();
    } else if (!strcmp(mode, "mixed")) {
        mixed();
    } else if (!strcmp(mode, "me")) {
        me_abuse();
    } else {
        fprintf(stderr, "unknown mode %s\n", mode);
        return 2;
    }
    dlclose(lib);
    return 0;
}
