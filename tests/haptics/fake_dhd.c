/* A fake of Force Dimension's dhd library, for the tests: the functions the trainer's backend
 * calls, an end effector the test places (in the device's frame: x towards the user, y right,
 * z up, m), the forces sent recorded, errors injected. The `fake_dhd_*` functions are the
 * test's controls. Built by the test with the system C compiler. */

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <string.h>

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static double position_m[3];
static unsigned int buttons;
static double last_force[3];
/* What reached the "motors": the largest force magnitude sent, and how many non-finite. */
static double largest_force;
static long nonfinite_forces;
static atomic_int pending_error;
static int last_error;
static atomic_long frames;
static int opened, closed, force_enabled, absent, refuse_force;
static double max_force = 9.5;
/* An error code the next dhdSetForce fails with (0: none). */
static atomic_int set_force_error;

int dhdOpen(void) {
    if (absent) { last_error = 3; return -1; }
    opened = 1;
    closed = 0;
    return 0;
}

int dhdClose(char id) { (void)id; closed = 1; return 0; }
int dhdEnableForce(unsigned char on, char id) {
    (void)id;
    if (refuse_force) { last_error = 7; return -1; }
    force_enabled = on;
    return 0;
}

int dhdGetPosition(double *x, double *y, double *z, char id) {
    (void)id;
    int error = atomic_exchange(&pending_error, 0);
    if (error) { last_error = error; return -1; }
    pthread_mutex_lock(&lock);
    *x = position_m[0];
    *y = position_m[1];
    *z = position_m[2];
    pthread_mutex_unlock(&lock);
    return 0;
}

int dhdGetOrientationFrame(double matrix[3][3], char id) {
    (void)id;
    memset(matrix, 0, 9 * sizeof(double));
    matrix[0][0] = matrix[1][1] = matrix[2][2] = 1.0;
    return 0;
}

unsigned int dhdGetButtonMask(char id) { (void)id; return buttons; }

int dhdSetForce(double fx, double fy, double fz, char id) {
    (void)id;
    int error = atomic_exchange(&set_force_error, 0);
    if (error) { last_error = error; atomic_fetch_add(&frames, 1); return -1; }
    pthread_mutex_lock(&lock);
    last_force[0] = fx;
    last_force[1] = fy;
    last_force[2] = fz;
    double norm = sqrt(fx * fx + fy * fy + fz * fz);
    if (!isfinite(norm)) nonfinite_forces++;
    else if (norm > largest_force) largest_force = norm;
    pthread_mutex_unlock(&lock);
    atomic_fetch_add(&frames, 1);
    return 0;
}

double dhdGetMaxForce(char id) { (void)id; return max_force; }
const char *dhdGetSystemName(char id) { (void)id; return "fake omega.3"; }
int dhdErrorGetLast(void) { return last_error; }
const char *dhdErrorGetStr(int error) {
    switch (error) {
    case 3: return "no device found";
    case 7: return "communication error";
    default: return "undocumented error";
    }
}
const char *dhdErrorGetLastStr(void) { return dhdErrorGetStr(last_error); }

/* The test's controls. */
void fake_dhd_set_absent(int yes) { absent = yes; }
void fake_dhd_set_effector(double x, double y, double z, unsigned int pressed) {
    pthread_mutex_lock(&lock);
    position_m[0] = x;
    position_m[1] = y;
    position_m[2] = z;
    buttons = pressed;
    pthread_mutex_unlock(&lock);
}
void fake_dhd_last_force(double *out) {
    pthread_mutex_lock(&lock);
    memcpy(out, last_force, sizeof last_force);
    pthread_mutex_unlock(&lock);
}
void fake_dhd_inject_error(int code) { atomic_store(&pending_error, code); }
long fake_dhd_frames(void) { return atomic_load(&frames); }
double fake_dhd_largest_force(void) {
    pthread_mutex_lock(&lock);
    double largest = largest_force;
    pthread_mutex_unlock(&lock);
    return largest;
}
long fake_dhd_nonfinite_forces(void) {
    pthread_mutex_lock(&lock);
    long count = nonfinite_forces;
    pthread_mutex_unlock(&lock);
    return count;
}
int fake_dhd_closed(void) { return closed; }
int fake_dhd_force_enabled(void) { return force_enabled; }
void fake_dhd_set_max_force(double newtons) { max_force = newtons; }
void fake_dhd_refuse_force(int yes) { refuse_force = yes; }
void fake_dhd_fail_set_force(int code) { atomic_store(&set_force_error, code); }
