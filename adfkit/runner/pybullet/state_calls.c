/* adfkit's PyBullet state calls in C: many bodies' base states read, and many torques and forces
 * applied, in one call from Python (state_calls.py builds and loads this file).
 *
 * PyBullet has no batched call for separate bodies, so the springs of AMBF's six-dof joints read
 * each free body with getBasePositionAndOrientation and getBaseVelocity and push it with
 * applyExternalTorque / applyExternalForce, ~150 Python calls a physics step. Here the same
 * requests go to the same physics server through PyBullet's own C API (b3RequestActualState...,
 * b3ApplyExternalForce...: the functions pybullet's module is built from, looked up in it), one
 * request a body as PyBullet makes them, so every number is the one the Python calls give.
 *
 * The physics client handle comes from PyBullet's plugin interface: loadPlugin calls
 * initPlugin_adfkit with a client of the world's own server (its plugin manager's), which Python
 * then takes with adfkit_last_client(). Nothing runs inside Bullet's step. */

#include <dlfcn.h>
#include <math.h>
#include <stddef.h>

/* SharedMemoryPublic.h of the Bullet PyBullet 3.2.7 is built from: a plugin answers it to load */
#define ADFKIT_PYBULLET_MAGIC 202010061
#define ADFKIT_WORLD_FRAME 2 /* EF_WORLD_FRAME */

typedef void *handle;
struct plugin_context { handle client; }; /* b3PluginContext: the client is its first field */

static handle (*request_state)(handle, int);
static handle (*submit)(handle, handle);
static int (*actual_state)(handle, int *, int *, int *, const double **, const double **, const double **,
                           const double **);
static handle (*force_init)(handle);
static void (*add_force)(handle, int, int, const double *, const double *, int);
static void (*add_torque)(handle, int, int, const double *, int);

static handle last_client;

int initPlugin_adfkit(struct plugin_context *context) {
    last_client = context->client;
    return ADFKIT_PYBULLET_MAGIC;
}

void exitPlugin_adfkit(struct plugin_context *context) { (void)context; }

int executePluginCommand_adfkit(struct plugin_context *context, const void *arguments) {
    (void)context;
    (void)arguments;
    return 0;
}

handle adfkit_last_client(void) {
    handle c = last_client;
    last_client = NULL;
    return c;
}

/* Looks PyBullet's C API up in its module (already loaded: its path). 0 when every function is there. */
int adfkit_bind(const char *pybullet_path) {
    void *lib = dlopen(pybullet_path, RTLD_NOW | RTLD_NOLOAD);
    if (lib == NULL) return -1;
    request_state = (handle(*)(handle, int))dlsym(lib, "b3RequestActualStateCommandInit");
    submit = (handle(*)(handle, handle))dlsym(lib, "b3SubmitClientCommandAndWaitStatus");
    actual_state = (int (*)(handle, int *, int *, int *, const double **, const double **, const double **,
                            const double **))dlsym(lib, "b3GetStatusActualState");
    force_init = (handle(*)(handle))dlsym(lib, "b3ApplyExternalForceCommandInit");
    add_force = (void (*)(handle, int, int, const double *, const double *, int))dlsym(lib, "b3ApplyExternalForce");
    add_torque = (void (*)(handle, int, int, const double *, int))dlsym(lib, "b3ApplyExternalTorque");
    return (request_state && submit && actual_state && force_init && add_force && add_torque) ? 0 : -2;
}

/* Each body's base position (3), quaternion (4), linear (3) and angular (3) velocity into out (n x 13),
 * as getBasePositionAndOrientation and getBaseVelocity give them. 0, or -(i+1) where body i failed. */
int adfkit_read_bases(handle client, int n, const int *uids, double *out) {
    for (int i = 0; i < n; i++) {
        const double *q = NULL, *qdot = NULL;
        int nq = 0, nu = 0;
        handle status = submit(client, request_state(client, uids[i]));
        if (!actual_state(status, NULL, &nq, &nu, NULL, &q, &qdot, NULL) || nq < 7 || nu < 6) return -(i + 1);
        double *row = out + 13 * i;
        for (int k = 0; k < 7; k++) row[k] = q[k];
        for (int k = 0; k < 6; k++) row[7 + k] = qdot[k];
    }
    return 0;
}

/* applyExternalTorque(uids[i], links[i], torques[i], WORLD_FRAME) for each i, one command each as
 * PyBullet's; then, where forces is not NULL, applyExternalForce(fuids[j], flinks[j], forces[j],
 * at[j], WORLD_FRAME) for each j < m. */
void adfkit_apply(handle client, int n, const int *uids, const int *links, const double *torques, int m,
                  const int *fuids, const int *flinks, const double *forces, const double *at) {
    for (int i = 0; i < n; i++) {
        handle cmd = force_init(client);
        add_torque(cmd, uids[i], links[i], torques + 3 * i, ADFKIT_WORLD_FRAME);
        submit(client, cmd);
    }
    if (forces == NULL) return;
    for (int j = 0; j < m; j++) {
        handle cmd = force_init(client);
        add_force(cmd, fuids[j], flinks[j], forces + 3 * j, at + 3 * j, ADFKIT_WORLD_FRAME);
        submit(client, cmd);
    }
}

/* AMBF's six-dof springs (spring_forces.py's "ambf" form) evaluated whole, for a SpringSet of free
 * bodies with no cone and no body held alone on a static one (spring_c.py): every joint's three
 * angular spring rows and limits, and the free-linear joints' spring, damper and limits at their
 * pivots, as SpringSet.apply computes them (the same formulas in the same order; numpy's rounding
 * differs where it uses BLAS and its own arctan2 and arcsin), then each body's torque and each
 * pushed body's force handed to PyBullet as adfkit_apply does. */
struct springs {
    int nb, nj, nf;
    const int *ip, *ic;                                   /* nj: each joint's parent and child body */
    const double *ra_in, *rb_in, *eq, *nk, *nc, *low, *high, *ieff; /* nj x 9, nj x 3 (ieff: nj) */
    const int *fl;                                        /* nf: the free-linear joints */
    const double *pa_in, *pb_in, *feq, *fnk, *fnc, *flow, *fhigh, *fg; /* nf x 3 */
    const double *inv_m, *inv_i;                          /* nb, nb x 3: shared 1/m, principal 1/I */
    int nd, np;
    const int *dyn, *duid, *dlink, *push, *puid, *plink;  /* the bodies pushed: torque, force */
    double *work;                                         /* nb x 9 + nj x 24 + nf x 18 */
};

static double clamp1(double v) { return v < -1.0 ? -1.0 : (v > 1.0 ? 1.0 : v); }
static void cross(const double *a, const double *b, double *o) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
/* m (3x3, rows) @ n */
static void mul33(const double *m, const double *n, double *o) {
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) o[3 * r + c] = (m[3 * r] * n[c] + m[3 * r + 1] * n[3 + c]) + m[3 * r + 2] * n[6 + c];
}
static void mulv(const double *m, const double *v, double *o) { /* m @ v */
    for (int r = 0; r < 3; r++) o[r] = (m[3 * r] * v[0] + m[3 * r + 1] * v[1]) + m[3 * r + 2] * v[2];
}
static void mulvt(const double *m, const double *v, double *o) { /* m^T @ v */
    for (int r = 0; r < 3; r++) o[r] = (m[r] * v[0] + m[3 + r] * v[1]) + m[6 + r] * v[2];
}
static double spring_row(double nk, double nc, double x, double v) { /* SpringSet._spring, D None */
    double spring = nk * x, damper = nc * v;
    return (spring * damper < 0.0 && fabs(damper) > fabs(spring)) ? damper : spring + damper;
}
/* SpringSet._limit on one axis: x, v (end of step), v0 (before), inertia; rows: AMBF's rows act */
static double limit_row(double x, double v, double v0, double lo, double hi, double in, double dt, double erp,
                        int rows) {
    double out = 0.0;
    int active = lo <= hi, over = active && x > hi, under = active && x < lo;
    if (over || under) {
        double err = over ? x - hi : x - lo;
        double f = in * (-erp * err / dt - v) / dt;
        out = over ? (f < 0.0 ? f : 0.0) : (f > 0.0 ? f : 0.0);
    }
    if (rows && lo < hi) {
        double gap_lo = x - lo, gap_hi = hi - x, v0_dt = v0 * dt;
        double slowest = (gap_lo > 0.0 && -v0_dt > gap_lo) ? 0.0 : -erp * gap_lo / dt;
        double fastest = (gap_hi > 0.0 && v0_dt > gap_hi) ? 0.0 : erp * gap_hi / dt;
        double up = in * (slowest - v) / dt, down = in * (fastest - v) / dt;
        out = (up > 0.0 ? up : 0.0) + (down < 0.0 ? down : 0.0);
    }
    return out;
}
static int heads_out(double x, double v, double lo, double hi, double dt, double erp) {
    if (!(lo < hi)) return 0;
    double ahead = x + v * (dt / erp);
    return ahead < lo || ahead > hi;
}
static int outside(double x, double lo, double hi) { return lo <= hi && (x > hi || x < lo); }

/* st: each body's position, quaternion (x, y, z, w), linear and angular velocity (nb x 13), as
 * adfkit_read_bases gives them; torque, force: nb x 3, written. */
int adfkit_springs_apply(handle client, struct springs *S, const double *st, double dt, double erp, double *torque,
                         double *force) {
    int nb = S->nb, nj = S->nj, nf = S->nf;
    double *rot = S->work, *ja = rot + 9 * nb, *lw = ja + 24 * nj;
    for (int b = 0; b < nb; b++) { /* quat_to_matrix */
        const double *q = st + 13 * b + 3;
        double x = q[0], y = q[1], z = q[2], w = q[3], *m = rot + 9 * b;
        double xx = x * x, yy = y * y, zz = z * z, xy = x * y, xz = x * z, yz = y * z, xw = x * w, yw = y * w,
               zw = z * w;
        m[0] = 1 - 2 * (yy + zz), m[1] = 2 * (xy - zw), m[2] = 2 * (xz + yw);
        m[3] = 2 * (xy + zw), m[4] = 1 - 2 * (xx + zz), m[5] = 2 * (yz - xw);
        m[6] = 2 * (xz - yw), m[7] = 2 * (yz + xw), m[8] = 1 - 2 * (xx + yy);
        for (int k = 0; k < 3; k++) torque[3 * b + k] = 0.0, force[3 * b + k] = 0.0;
    }
    int rows = 0, out = 0;
    for (int j = 0; j < nj; j++) { /* the angular rows: frames, angles, spring */
        double *s = ja + 24 * j; /* ra (9), ang (3), w (3), tau (3), v (3), spare (3) */
        double rb[9], rel[9], dw[3];
        mul33(rot + 9 * S->ip[j], S->ra_in + 9 * j, s);
        mul33(rot + 9 * S->ic[j], S->rb_in + 9 * j, rb);
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) rel[3 * r + c] = (s[r] * rb[c] + s[3 + r] * rb[3 + c]) + s[6 + r] * rb[6 + c];
        double *ang = s + 9, *w = s + 12, *tau = s + 15, *v = s + 18;
        ang[0] = atan2(-rel[5], rel[8]);
        ang[1] = asin(clamp1(rel[2]));
        ang[2] = atan2(-rel[1], rel[0]);
        for (int k = 0; k < 3; k++) dw[k] = st[13 * S->ic[j] + 10 + k] - st[13 * S->ip[j] + 10 + k];
        mulvt(s, dw, w);
        for (int k = 0; k < 3; k++) {
            int a = 3 * j + k;
            tau[k] = spring_row(S->nk[a], S->nc[a], ang[k] - S->eq[a], w[k]);
            v[k] = w[k] + tau[k] * dt / S->ieff[j];
            out |= outside(ang[k], S->low[a], S->high[a]);
            rows |= heads_out(ang[k], v[k], S->low[a], S->high[a], dt, erp);
        }
    }
    for (int j = 0; j < nj; j++) { /* their limits, the torques into the world */
        double *s = ja + 24 * j, *tau = s + 15, tw[3];
        if (out || rows)
            for (int k = 0; k < 3; k++) {
                int a = 3 * j + k;
                tau[k] += limit_row(s[9 + k], s[18 + k], s[12 + k], S->low[a], S->high[a], S->ieff[j], dt, erp, rows);
            }
        mulv(s, tau, tw);
        for (int k = 0; k < 3; k++) torque[3 * S->ic[j] + k] += tw[k], torque[3 * S->ip[j] + k] -= tw[k];
    }
    rows = 0, out = 0;
    for (int i = 0; i < nf; i++) { /* free linear axes: pivots, offset, velocities, spring */
        int j = S->fl[i], p = S->ip[j], c = S->ic[j];
        const double *ra = ja + 24 * j, *pp = st + 13 * p, *pc = st + 13 * c;
        double *l = lw + 12 * i; /* d (3), v_rel (3), f (3), m (3) */
        double pa[3], pbw[3], arm_p[3], arm_c[3], vp[3], vc[3], t[3], dv[3], dd[3];
        mulv(rot + 9 * p, S->pa_in + 3 * i, t);
        for (int k = 0; k < 3; k++) pa[k] = pp[k] + t[k];
        mulv(rot + 9 * c, S->pb_in + 3 * i, t);
        for (int k = 0; k < 3; k++) pbw[k] = pc[k] + t[k];
        for (int k = 0; k < 3; k++) dd[k] = pbw[k] - pa[k], arm_p[k] = pa[k] - pp[k], arm_c[k] = pbw[k] - pc[k];
        mulvt(ra, dd, l);
        cross(pp + 10, arm_p, t);
        for (int k = 0; k < 3; k++) vp[k] = pp[7 + k] + t[k];
        cross(pc + 10, arm_c, t);
        for (int k = 0; k < 3; k++) vc[k] = pc[7 + k] + t[k], dv[k] = vc[k] - vp[k];
        mulvt(ra, dv, l + 3);
        /* the pivot B's mass along each axis of frame A, both bodies pushed there (_pivot_mass) */
        double rp[3], rc[3];
        for (int k = 0; k < 3; k++) rp[k] = pbw[k] - pp[k], rc[k] = pbw[k] - pc[k];
        for (int a = 0; a < 3; a++) {
            double axis[3] = {ra[a], ra[3 + a], ra[6 + a]}, total = 0.0;
            for (int e = 0; e < 2; e++) {
                int b = e ? c : p;
                double rxa[3], pr[3], sum;
                cross(e ? rc : rp, axis, rxa);
                mulvt(rot + 9 * b, rxa, pr); /* rxa @ rot: its principal-frame components */
                sum = (pr[0] * pr[0] * S->inv_i[3 * b] + pr[1] * pr[1] * S->inv_i[3 * b + 1]) +
                      pr[2] * pr[2] * S->inv_i[3 * b + 2];
                total += S->inv_m[b] + sum;
            }
            l[9 + a] = 1.0 / (total > 1e-12 ? total : 1e-12);
        }
        double g[3];
        mulvt(ra, S->fg + 3 * i, g);
        for (int k = 0; k < 3; k++) {
            int a = 3 * i + k;
            l[6 + k] = spring_row(S->fnk[a], S->fnc[a], l[k] - S->feq[a], l[3 + k]);
            double v = l[3 + k] + (l[6 + k] / l[9 + k] + g[k]) * dt;
            out |= outside(l[k], S->flow[a], S->fhigh[a]);
            rows |= heads_out(l[k], v, S->flow[a], S->fhigh[a], dt, erp);
        }
        double *keep = lw + 12 * nf + 3 * i; /* pivot B and g_rel for the second pass */
        for (int k = 0; k < 3; k++) keep[k] = pbw[k], keep[3 * nf + k] = g[k];
    }
    for (int i = 0; i < nf; i++) { /* their limits, forces and moments */
        int j = S->fl[i], p = S->ip[j], c = S->ic[j];
        const double *ra = ja + 24 * j, *l = lw + 12 * i;
        const double *pbw = lw + 12 * nf + 3 * i, *g = pbw + 3 * nf;
        double f[3], fw[3], mom[3], arm[3];
        for (int k = 0; k < 3; k++) {
            int a = 3 * i + k;
            double v = l[3 + k] + (l[6 + k] / l[9 + k] + g[k]) * dt;
            f[k] = l[6 + k];
            if (out || rows) f[k] += limit_row(l[k], v, l[3 + k], S->flow[a], S->fhigh[a], l[9 + k], dt, erp, rows);
        }
        mulv(ra, f, fw);
        for (int k = 0; k < 3; k++) force[3 * c + k] += fw[k], force[3 * p + k] -= fw[k];
        for (int k = 0; k < 3; k++) arm[k] = pbw[k] - st[13 * c + k];
        cross(arm, fw, mom);
        for (int k = 0; k < 3; k++) torque[3 * c + k] += mom[k];
        for (int k = 0; k < 3; k++) arm[k] = pbw[k] - st[13 * p + k];
        cross(arm, fw, mom);
        for (int k = 0; k < 3; k++) torque[3 * p + k] -= mom[k];
    }
    for (int i = 0; i < S->nd; i++) {
        handle cmd = force_init(client);
        add_torque(cmd, S->duid[i], S->dlink[i], torque + 3 * S->dyn[i], ADFKIT_WORLD_FRAME);
        submit(client, cmd);
    }
    for (int i = 0; i < S->np; i++) {
        handle cmd = force_init(client);
        add_force(cmd, S->puid[i], S->plink[i], force + 3 * S->push[i], st + 13 * S->push[i], ADFKIT_WORLD_FRAME);
        submit(client, cmd);
    }
    return 0;
}

/* numpy's 3-vector dot product as its BLAS (OpenBLAS's ddot) rounds it: one fused multiply-add after another */
static double dot3(const double *a, const double *b) { return fma(a[2], b[2], fma(a[1], b[1], a[0] * b[0])); }

/* AMBF's ghost rule on a multibody link (ghost_steps.ambf_ghost: ghost_rules.ghost_accelerations,
 * then m·a and rot·(I ∘ rotᵀ·α)) with numpy's rounding as this machine's OpenBLAS gives it (its
 * dot as dot3, its 3x3 matrix-vector products in the order of the fused multiply-adds below; the
 * rest is numpy's elementwise arithmetic, one IEEE operation each, the same here).
 * in: v (3), w (3), the ghost parent's v (3), keep (AMBF_GHOST_KEEP^points), cdt, mass, inertia
 * (3), rot (3x3, rows: the centre of mass frame's); out: force (3), torque (3). */
void adfkit_ghost_link(const double *in, double along_from, double *out) {
    const double *v = in, *w = in + 3, *vp = in + 6, *inertia = in + 12, *r = in + 15;
    double keep = in[9], cdt = in[10], mass = in[11], a[3], alpha[3], t[3], u[3];
    double slow = vp[0] * vp[0] + vp[1] * vp[1] + vp[2] * vp[2]; /* kept_under_slow_parent's sum */
    if (slow > along_from * along_from * (1.0 - 1e-9)) {
        double mag = sqrt(dot3(vp, vp)), along[3] = {0.0, 0.0, 0.0};
        if (mag > along_from) {
            double s = dot3(v, vp) / (mag * mag);
            for (int k = 0; k < 3; k++) along[k] = vp[k] * s;
        }
        for (int k = 0; k < 3; k++) {
            a[k] = ((keep * (v[k] - along[k]) + vp[k]) - v[k]) / cdt;
            alpha[k] = (keep * w[k] - w[k]) / cdt;
        }
    } else
        for (int k = 0; k < 3; k++) {
            a[k] = ((keep * (v[k] - 0.0) + vp[k]) - v[k]) / cdt;
            alpha[k] = (keep * w[k] - w[k]) / cdt;
        }
    for (int k = 0; k < 3; k++) out[k] = mass * a[k];
    for (int i = 0; i < 3; i++) t[i] = fma(r[6 + i], alpha[2], fma(r[3 + i], alpha[1], r[i] * alpha[0])); /* rotᵀ·α */
    for (int i = 0; i < 3; i++) u[i] = inertia[i] * t[i];
    for (int i = 0; i < 3; i++) out[3 + i] = fma(r[3 * i + 2], u[2], fma(r[3 * i], u[0], r[3 * i + 1] * u[1])); /* rot·u */
}
