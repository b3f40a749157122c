/* A hostile FMI 3.0 master in C: loads an FMU binary with dlopen and drives its fmi3* functions the way a
 * careless or malicious tool would. Each mode prints one summary line "ok ..." and exits 0, or prints what
 * went wrong and exits 1. Run under valgrind / a timeout by tests/test_fmi3_hardening.py.
 *
 *   fmi3_hostile LIB TOKEN cycles N   instantiate/init/step/state/serialize/deserialize/free N times:
 *                                     every cycle gives the same bits
 *   fmi3_hostile LIB TOKEN abuse      NULL and foreign pointers, wrong states, NaN, bool bytes other than
 *                                     0/1, wrong counts, every refused function: the prescribed status,
 *                                     a log message naming the function, and the instance recovers
 *   fmi3_hostile LIB TOKEN mixed      an FMI 2.0 and an FMI 3.0 instance of the same library side by side
 *                                     give identical results; neither API accepts the other's instance
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
enum { VR_TORQUE_CMD_X = 0, VR_W_X = 14, VR_INIT_W_X = 113, VR_MTQ_ENABLE = 144 };
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
    I (*inst_me)(const char *, const char *, const char *, bool, bool, void *, Log3) = sym("fmi3InstantiateModelExchange");
    CHECK(!inst_me("me", TOKEN, NULL, false, false, NULL, log3), "Model Exchange instantiated");
    CHECK(strstr(last_msg, "fmi3InstantiateModelExchange"), "ME message");
    /* the instance still works after all that */
    CHECK(reset(c) == OK && enter_init(c, false, 0, 0, false, 0) == OK && exit_init(c) == OK, "final init");
    CHECK(step(c, 0, 0.1) == OK, "final step");
    CHECK(get_f64(c, &tvr, 1, &v, 1) == OK && v == 0.1, "time after a step");
    free_instance(c);
    free_instance(c); /* double free: ignored */
    printf("ok abuse (%d log messages)\n", n_msgs);
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
    } else {
        fprintf(stderr, "unknown mode %s\n", mode);
        return 2;
    }
    dlclose(lib);
    return 0;
}
