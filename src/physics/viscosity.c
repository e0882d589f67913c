/* Gravity plus Morris 1997 viscosity, with Akinci 2012 wall friction (per solid: no slip with
 * the fluid's or the solid's own viscosity, or free slip). */
#include "physics/viscosity.h"

#include "core/hits.h"
#include "core/nlist.h"
#include "physics/pair_terms.h"
#include "physics/pressure.h"
#include "pfsph/thermostat.h"
#include "physics/solver.h"
#include "physics/stages.h"

/* particle i as its fluid pairs see it */
typedef struct visc_i {
    pfsph_real x, y, z, vx, vy, vz, nu, ndr; /* ndr: delta_i as stored (the pair's mean density) */
    double m, nd;
    uint32_t id;
    int phase;
} visc_i;

typedef struct visc_acc {
    pfsph_real ax, ay, az; /* viscosity sum */
    double fx, fy, fz;     /* thermostat */
} visc_acc;

/* a[0..2] += sum_q s[q] x_ij[q], q < n: one after another, or the eight-lane total */
typedef void (*visc_sum_fn)(int n, const pfsph_real *s, const pfsph_real *dx, const pfsph_real *dy,
                            const pfsph_real *dz, pfsph_real *a);
static void sum_ordered(int n, const pfsph_real *s, const pfsph_real *dx, const pfsph_real *dy, const pfsph_real *dz,
                        pfsph_real *a)
{
    pfsph_real ax = a[0], ay = a[1], az = a[2];
    for (int q = 0; q < n; q++) {
        ax += s[q] * dx[q];
        ay += s[q] * dy[q];
        az += s[q] * dz[q];
    }
    a[0] = ax, a[1] = ay, a[2] = az;
}
static void sum_lanes(int n, const pfsph_real *s, const pfsph_real *dx, const pfsph_real *dy, const pfsph_real *dz,
                      pfsph_real *a)
{
    pfsph_real t[3];
    pfsph__lanes_sx(n, s, dx, dy, dz, t);
    a[0] += t[0], a[1] += t[1], a[2] += t[2];
}

/* Fluid neighbour j's Morris viscosity term (and with thermo its thermostat force) on i, added
 * to acc; x_ij = (dx, dy, dz), r2 = |x_ij|^2 < h^2, dwr = pfsph_kernel_dw_r(|x_ij|). The factor
 * 2 nu / (delta_i + delta_j) (v_ij . x_ij) / (r2 + eps) dW/r has the same bits seen from j. */
static inline void visc_pair(const pfsph_ctx *ctx, const visc_i *I, uint32_t j, pfsph_real dx, pfsph_real dy,
                             pfsph_real dz, pfsph_real r2, pfsph_real dwr, pfsph_real eps, const int thermo, double amp,
                             const double ts[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES], uint64_t key, visc_acc *acc)
{
    const pfsph_particles *f = ctx->fluid;
    const int pb = f->phase[j];
    pfsph_real nu = pfsph__visc_pair_nu(ctx, I->phase, pb);
    pfsph_real vdx = (I->vx - f->vx[j]) * dx + (I->vy - f->vy[j]) * dy + (I->vz - f->vz[j]) * dz;
    pfsph_real s = 2 * nu / (I->ndr + ctx->nd[j]) * vdx / (r2 + eps) * dwr;
    acc->ax += s * dx;
    acc->ay += s * dy;
    acc->az += s * dz;
    if (thermo) {
        const double nud = pfsph__visc_noise_nu(ctx, I->phase, pb, I->nd, (double)ctx->nd[j]);
        if (nud > 0 && r2 > 0) {
            const double rd = sqrt((double)r2);
            /* dwr, not dw_r((real) rd): (real) sqrt((double) r2) is pfsph_sqrt(r2), so the same bits */
            const double t =
                pfsph__thermo_fluid(amp * ts[I->phase][pb], nud, I->m, (double)ctx->mass[pb], I->nd, (double)ctx->nd[j],
                                    (double)r2, (double)dwr, (double)eps, rd, pfsph_thermo_theta(key, I->id, f->id[j]));
            acc->fx += t * (double)dx;
            acc->fy += t * (double)dy;
            acc->fz += t * (double)dz;
        }
    }
}

/* Boundary particle j's Akinci 2012 friction term on i (and with thermo the thermostat's wall
 * force, of amplitude ampw), added to acc; x_ij = (dx, dy, dz), r2 < h^2, dwr its kernel
 * derivative. The friction sum is scaled by the fluid's viscosity by the caller unless the
 * wall table is in use (ctx.h). */
static inline void wall_pair(const pfsph_ctx *ctx, const visc_i *I, uint32_t j, pfsph_real dx, pfsph_real dy,
                             pfsph_real dz, pfsph_real r2, pfsph_real dwr, pfsph_real eps, const int thermo,
                             double ampw, uint64_t wkey, visc_acc *acc)
{
    const pfsph_particles *b = ctx->boundary;
    const int mixed = ctx->nwalls > 1;
    pfsph_real vdx = (I->vx - b->vx[j]) * dx + (I->vy - b->vy[j]) * dy + (I->vz - b->vz[j]) * dz;
    /* the boundary particle's volume V_b plays the role of m_j / rho_j */
    pfsph_real s = b->aux[j] * vdx / (r2 + eps) * dwr;
    if (mixed) s *= ctx->wall_scale[b->wall[j]] * I->nu + ctx->wall_nu[b->wall[j]];
    acc->ax += s * dx;
    acc->ay += s * dy;
    acc->az += s * dz;
    if (thermo && r2 > 0) {
        const double rd = sqrt((double)r2);
        const double nuw = mixed
            ? (double)ctx->wall_scale[b->wall[j]] * (double)I->nu + (double)ctx->wall_nu[b->wall[j]]
            : (double)I->nu;
        /* dwr, not dw_r((real) rd): (real) sqrt((double) r2) is pfsph_sqrt(r2), so the same bits */
        const double t = pfsph__thermo_wall(ampw, nuw, I->m, (double)b->aux[j], (double)r2, (double)dwr, (double)eps,
                                            rd, pfsph_thermo_theta(wkey, I->id, b->id[j]));
        acc->fx += t * (double)dx;
        acc->fy += t * (double)dy;
        acc->fz += t * (double)dz;
    }
}

/* Per-hit inputs of the thermostat's vector terms (pfsph__terms_thermo), one thread's. */
typedef struct thermo_buf {
    double amp_ts[PFSPH_HITS_CAP + PFSPH_HITS_PAD], nu[PFSPH_HITS_CAP + PFSPH_HITS_PAD],
        mj[PFSPH_HITS_CAP + PFSPH_HITS_PAD], ndj[PFSPH_HITS_CAP + PFSPH_HITS_PAD],
        theta[PFSPH_HITS_CAP + PFSPH_HITS_PAD], t[PFSPH_HITS_CAP + PFSPH_HITS_PAD];
    uint32_t idj[PFSPH_HITS_CAP + PFSPH_HITS_PAD];
} thermo_buf;

/* The fluid hits in H of particle I with the thermostat: viscosity (and fused, pressure) factors
 * and the noise force in vector code, added in the hits' order to their sums; the same terms
 * and order as visc_pair over the hits, so the same bits. */
static inline void thermo_hits(const pfsph_ctx *ctx, const visc_i *I, pfsph_hits *H, thermo_buf *X,
                               const pfsph_pair_in *in, pfsph_real eps, double amp,
                               const double ts[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES], uint64_t key, const int fused,
                               const int one_phase, visc_acc *acc, pfsph_real pa3[3])
{
    const pfsph_particles *f = ctx->fluid;
    const int n = H->n;
    /* whole vectors: padding hits (j = 0, r2 = 0) give terms that are not summed */
    const int n16 = pfsph_hits_pad16(H);
    if (one_phase) /* the per-phase inputs were filled once (thermo_fill_phase) */
        for (int e = 0; e < n16; e++) {
            const uint32_t j = H->j[e];
            X->ndj[e] = (double)ctx->nd[j];
            X->idj[e] = f->id[j];
        }
    else
        for (int e = 0; e < n16; e++) {
            const uint32_t j = H->j[e];
            const int pb = f->phase[j];
            H->t3[e] = pfsph__visc_pair_nu(ctx, I->phase, pb);
            X->amp_ts[e] = amp * ts[I->phase][pb];
            X->ndj[e] = (double)ctx->nd[j];
            X->nu[e] = pfsph__visc_noise_nu(ctx, I->phase, pb, I->nd, X->ndj[e]);
            X->mj[e] = (double)ctx->mass[pb];
            X->idj[e] = f->id[j];
        }
    /* the pair hashes in vector code (pair_terms.c), the same bits as pfsph_thermo_theta */
    pfsph__terms_theta(key, I->id, n16, X->idj, X->theta);
    pfsph__terms_visc_pressure(in, n16, H->j, H->dx, H->dy, H->dz, H->r2, H->t0, H->t1, H->t2);
    pfsph__terms_thermo(I->m, I->nd, (double)eps, n16, H->r2, H->t0, X->amp_ts, X->nu, X->mj, X->ndj, X->theta, X->t);
    for (int e = 0; e < n; e++) {
        acc->ax += H->t1[e] * H->dx[e];
        acc->ay += H->t1[e] * H->dy[e];
        acc->az += H->t1[e] * H->dz[e];
    }
    for (int e = 0; e < n; e++)
        if (X->nu[e] > 0 && H->r2[e] > 0) {
            acc->fx += X->t[e] * (double)H->dx[e];
            acc->fy += X->t[e] * (double)H->dy[e];
            acc->fz += X->t[e] * (double)H->dz[e];
        }
    if (fused)
        for (int e = 0; e < n; e++) {
            pa3[0] += H->t2[e] * H->dx[e];
            pa3[1] += H->t2[e] * H->dy[e];
            pa3[2] += H->t2[e] * H->dz[e];
        }
}

/* The fluid's phase if all its particles have one (else -1). */
static int fluid_one_phase(const pfsph_particles *f)
{
    if (!f->n) return -1;
    const uint8_t p0 = f->phase[0];
    uint8_t diff = 0;
    for (size_t i = 0; i < f->n; i++) diff |= (uint8_t)(f->phase[i] ^ p0);
    return diff ? -1 : p0;
}

/* With one fluid phase pa the per-hit inputs of thermo_hits that depend on the phases alone are
 * the same for every hit: written once per thread over the whole buffer, with the expressions
 * of thermo_hits (the same values). */
static void thermo_fill_phase(const pfsph_ctx *ctx, int pa, pfsph_hits *H, thermo_buf *X, double amp,
                              const double ts[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES])
{
    const pfsph_real nua = ctx->nu[pa];
    for (int e = 0; e < PFSPH_HITS_CAP + PFSPH_HITS_PAD; e++) {
        H->t3[e] = pfsph__visc_pair_nu(ctx, pa, pa);
        X->amp_ts[e] = amp * ts[pa][pa];
        X->nu[e] = 0.5 * ((double)nua + (double)nua);
        X->mj[e] = (double)ctx->mass[pa];
    }
}

/* thermo: also the thermostat's random forces (thermostat.h), fused into this pass so that the
 * neighbours within h are walked once; the same expressions as pfsph_thermostat_apply, so the
 * same bits. fused: also the pressure acceleration of pfsph__pressure_accel (at the fluid's
 * positions, with ctx->nd and p) into ap, in the same walk (grid walks only: WCSPH, whose
 * pressure needs the density alone); each sum keeps its terms and order, so the same bits as
 * the two passes. Specialised at compile time (call sites with constants). */
static inline void nonpressure(const pfsph_ctx *ctx, pfsph_real *const noise[3], const int thermo, const int fused,
                               const pfsph_real *p, pfsph_real *const ap[3])
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real h2 = k->h * k->h, eps = (pfsph_real)0.01 * h2;
    const pfsph_real gx = (pfsph_real)ctx->gravity[0], gy = (pfsph_real)ctx->gravity[1],
                     gz = (pfsph_real)ctx->gravity[2];
    /* Morris et al. 1997 / SPlisHSPlasH "standard" viscosity: 2(d+2) nu sum_j (m_j/rho_j)
     * (v_ij . x_ij)/(|x_ij|^2 + 0.01 h^2) grad W_ij, with m_j/rho_j the pair's mean 2 /
     * (delta_i + delta_j): the same factor from both sides, so each pair's friction is equal
     * and opposite (with 1/delta_j alone it was not where delta_i != delta_j: a surface, a
     * wall, an interface; a free drop stirred by a body lost 1e-3 of its momentum, issue 31),
     * and it is the friction of the thermostat's noise (fluctuation-dissipation per pair). */
    const pfsph_real visc_c = (pfsph_real)(2 * (ctx->dim + 2));
    const size_t n = f->n;
    const int mixed = ctx->nwalls > 1;
    const pfsph_nlist *nl = ctx->nlist, *bl = ctx->nlist_b; /* the step's lists, when the solver built them */
    const pfsph_real wall_nu_max = ctx->wall_nu_max;
    const pfsph_real *nd = ctx->nd, inv_v0 = (pfsph_real)1 / ctx->V0;
    const pfsph_hits_fn hits = pfsph_hits_select();
    const int phase1 = thermo && !nl ? fluid_one_phase(f) : -1, one_phase = phase1 >= 0;
    double amp = 0, ts[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    /* each phase pair's viscosity for the list walk's vector loop (pfsph__visc_pair_nu) */
    pfsph_real nu_pair[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES];
    for (int a = 0; a < ctx->nphases; a++)
        for (int c = 0; c < ctx->nphases; c++) nu_pair[a][c] = pfsph__visc_pair_nu(ctx, a, c);
    uint64_t key = 0, wkey = 0;
    if (thermo) {
        amp = pfsph__thermo_amp(ctx);
        for (int a = 0; a < ctx->nphases; a++)
            for (int c = 0; c < ctx->nphases; c++)
                ts[a][c] = fmin(pfsph_thermostat_scale(ctx, a), pfsph_thermostat_scale(ctx, c));
        key = pfsph_thermo_step_key(ctx->seed, ctx->step, 0);
        wkey = pfsph_thermo_step_key(ctx->seed, ctx->step, PFSPH_THERMO_SALT_WALL);
    }
    /* the list walk's sums: in the list's order, or in the interactive mode in eight lanes
     * (docs/interactive.md, "The fifth pass"; IISPH's and DFSPH's physical lists keep the order) */
    const visc_sum_fn list_sum = ctx->interactive ? sum_lanes : sum_ordered;
#pragma omp parallel
    {
        pfsph_hits H;
        thermo_buf Xb, *X = thermo ? &Xb : NULL;
        (void)X;
        if (thermo && one_phase) thermo_fill_phase(ctx, phase1, &H, X, amp, ts);
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++) {
            const pfsph_real xi = f->x[i], yi = f->y[i], zi = f->z[i];
            const pfsph_real vxi = f->vx[i], vyi = f->vy[i], vzi = f->vz[i];
            const int pa = f->phase[i];
            const pfsph_real nui = ctx->nu[pa];
            const double mi = (double)ctx->mass[pa], ndi = thermo ? (double)ctx->nd[i] : 0;
            const uint32_t idi = f->id[i];
            const pfsph_real pi = fused ? p[i] / (nd[i] * nd[i]) : 0;
            pfsph_real pax = 0, pay = 0, paz = 0; /* pressure (fused) */
            double fx = 0, fy = 0, fz = 0;        /* thermostat */
            pfsph_real ax = 0, ay = 0, az = 0;
            pfsph_ranges r;
            /* the same terms in the same order from a list or a grid walk: the same bits */
            const visc_i vi = {xi, yi, zi, vxi, vyi, vzi, nui, nd[i], mi, ndi, idi, pa};
            visc_acc acc = {0, 0, 0, 0, 0, 0};
            if (nl && !thermo) {
                /* visc_pair's factor in vector code (pair_terms.c), added by list_sum */
                const pfsph_pair_in in = {*k, f->vx, f->vy, f->vz, nd, nd, NULL, vxi, vyi, vzi, nui, 0, eps, nd[i]};
                for (uint32_t e = nl->start[i], end = nl->start[i + 1]; e < end;) {
                    const uint32_t e1 = end - e > PFSPH_LIST_TERMS_MAX ? e + PFSPH_LIST_TERMS_MAX : end;
                    const int m = (int)(e1 - e);
                    pfsph__terms_visc_list(&in, f->x, f->y, f->z, f->phase, nu_pair[pa], xi, yi, zi, m, nl->idx + e,
                                           nl->dw + e, H.dx, H.dy, H.dz, H.t1);
                    pfsph_real a3[3] = {acc.ax, acc.ay, acc.az};
                    list_sum(m, H.t1, H.dx, H.dy, H.dz, a3);
                    acc.ax = a3[0], acc.ay = a3[1], acc.az = a3[2];
                    e = e1;
                }
            } else if (nl) {
                for (uint32_t e = nl->start[i]; e < nl->start[i + 1]; e++) {
                    const uint32_t j = nl->idx[e];
                    pfsph_real dx = xi - f->x[j], dy = yi - f->y[j], dz = zi - f->z[j];
                    visc_pair(ctx, &vi, j, dx, dy, dz, dx * dx + dy * dy + dz * dz, nl->dw[e], eps, thermo, amp, ts,
                              key, &acc);
                }
            } else {
                pfsph_grid_ranges(ctx->grid, xi, yi, zi, &r);
                /* the pairs within h of the grid walk, in its order */
                if (thermo) {
                    const pfsph_pair_in in = {*k,  f->vx, f->vy, f->vz, nd,  fused ? p : nd, H.t3, vxi,
                                              vyi, vzi,   nui,   pi,    eps, nd[i]};
                    pfsph_real pa3[3] = {0, 0, 0};
                    PFSPH_HITS_WALK(hits, &H, r, f->x, f->y, f->z, xi, yi, zi, h2, (uint32_t)i,
                                    thermo_hits(ctx, &vi, &H, X, &in, eps, amp, ts, key, fused, one_phase, &acc, pa3));
                    pax = pa3[0], pay = pa3[1], paz = pa3[2];
                } else {
                    /* the factors of visc_pair and of the pressure term in vector code
                     * (pair_terms.c), added in order: the same bits */
                    const pfsph_pair_in in = {*k,  f->vx, f->vy, f->vz, nd,  fused ? p : nd, H.t3, vxi,
                                              vyi, vzi,   nui,   pi,    eps, nd[i]};
                    PFSPH_HITS_WALK(hits, &H, r, f->x, f->y, f->z, xi, yi, zi, h2, (uint32_t)i, {
                        for (int e = 0; e < H.n; e++) H.t3[e] = pfsph__visc_pair_nu(ctx, pa, f->phase[H.j[e]]);
                        pfsph__terms_visc_pressure(&in, H.n, H.j, H.dx, H.dy, H.dz, H.r2, H.t0, H.t1, H.t2);
                        for (int e = 0; e < H.n; e++) {
                            acc.ax += H.t1[e] * H.dx[e];
                            acc.ay += H.t1[e] * H.dy[e];
                            acc.az += H.t1[e] * H.dz[e];
                        }
                        if (fused)
                            for (int e = 0; e < H.n; e++) {
                                pax += H.t2[e] * H.dx[e];
                                pay += H.t2[e] * H.dy[e];
                                paz += H.t2[e] * H.dz[e];
                            }
                    });
                }
            }
            ax = acc.ax, ay = acc.ay, az = acc.az, fx = acc.fx, fy = acc.fy, fz = acc.fz;
            /* Akinci 2012 boundary friction, with the fluid's own viscosity unless the solid
             * says otherwise (ctx wall tables: free slip, its own viscosity); static walls rest,
             * body particles move. With only default walls the table is skipped and the sum is
             * the one of a single viscosity, nui times the sum. */
            const int wall_visc = b->n && (nui > 0 || (mixed && wall_nu_max > 0));
            if (wall_visc && bl) {
                /* the same terms in the same order from the step's boundary list */
                visc_acc w = {0, 0, 0, fx, fy, fz};
                const double ampw = thermo ? amp * ts[pa][pa] : 0;
                for (uint32_t e = bl->start[i]; e < bl->start[i + 1]; e++) {
                    const uint32_t j = bl->idx[e];
                    pfsph_real dx = xi - b->x[j], dy = yi - b->y[j], dz = zi - b->z[j];
                    wall_pair(ctx, &vi, j, dx, dy, dz, dx * dx + dy * dy + dz * dz, bl->dw[e], eps, thermo, ampw, wkey,
                              &w);
                }
                fx = w.fx, fy = w.fy, fz = w.fz;
                const pfsph_real nub = mixed ? (pfsph_real)1 : nui;
                ax += nub * w.ax;
                ay += nub * w.ay;
                az += nub * w.az;
            } else if (wall_visc || (fused && b->n && pi > 0)) {
                /* the same friction over a grid walk; fused: the wall's pressure term
                 * (pfsph__pressure_accel) in the same walk */
                visc_acc w = {0, 0, 0, fx, fy, fz};
                pfsph_real bx = 0, by = 0, bz = 0;
                const double ampw = thermo ? amp * ts[pa][pa] : 0;
                const int wall_p = fused && pi > 0;
                pfsph_grid_ranges(ctx->bgrid, xi, yi, zi, &r);
                PFSPH_HITS_WALK(
                    hits, &H, r, b->x, b->y, b->z, xi, yi, zi, h2, UINT32_MAX, for (int e = 0; e < H.n; e++) {
                        const uint32_t j = H.j[e];
                        const pfsph_real dwr = pfsph_kernel_dw_r(k, pfsph_sqrt(H.r2[e]));
                        if (wall_visc)
                            wall_pair(ctx, &vi, j, H.dx[e], H.dy[e], H.dz[e], H.r2[e], dwr, eps, thermo, ampw, wkey,
                                      &w);
                        if (wall_p) {
                            const pfsph_real sb = b->aux[j] * dwr;
                            bx += sb * H.dx[e];
                            by += sb * H.dy[e];
                            bz += sb * H.dz[e];
                        }
                    });
                if (wall_visc) {
                    fx = w.fx, fy = w.fy, fz = w.fz;
                    const pfsph_real nub = mixed ? (pfsph_real)1 : nui;
                    ax += nub * w.ax;
                    ay += nub * w.ay;
                    az += nub * w.az;
                }
                if (wall_p) {
                    /* Akinci 2012: the wall pushes with p_i alone (pressure.c) */
                    const pfsph_real wb = pi * inv_v0;
                    pax += wb * bx;
                    pay += wb * by;
                    paz += wb * bz;
                }
            }
            if (fused) {
                const pfsph_real inv_m = -(pfsph_real)1 / ctx->mass[pa];
                ap[0][i] = inv_m * pax;
                ap[1][i] = inv_m * pay;
                ap[2][i] = inv_m * paz;
            }
            ctx->ax[i] = gx + visc_c * ax;
            ctx->ay[i] = gy + visc_c * ay;
            ctx->az[i] = gz + visc_c * az;
            if (thermo) {
                const pfsph_real nx = (pfsph_real)(fx / mi), ny = (pfsph_real)(fy / mi), nz = (pfsph_real)(fz / mi);
                noise[0][i] = nx;
                noise[1][i] = ny;
                noise[2][i] = nz;
                ctx->ax[i] += nx;
                ctx->ay[i] += ny;
                ctx->az[i] += nz;
            }
        }
    }
}

void pfsph__nonpressure(const pfsph_ctx *ctx) { nonpressure(ctx, NULL, 0, 0, NULL, NULL); }

void pfsph__nonpressure_thermo(const pfsph_ctx *ctx, pfsph_real *const noise[3])
{
    if (pfsph_thermostat_kT(ctx) > 0 && ctx->dt > 0) nonpressure(ctx, noise, 1, 0, NULL, NULL);
    else nonpressure(ctx, NULL, 0, 0, NULL, NULL);
}

void pfsph__forces_and_pressure(const pfsph_ctx *ctx, pfsph_real *const noise[3], const pfsph_real *p,
                                pfsph_real *const ap[3])
{
    const int thermo = noise && pfsph_thermostat_kT(ctx) > 0 && ctx->dt > 0;
    if (ctx->nlist) { /* lists are walked pass by pass */
        if (thermo) nonpressure(ctx, noise, 1, 0, NULL, NULL);
        else nonpressure(ctx, NULL, 0, 0, NULL, NULL);
        pfsph__pressure_accel(ctx, ctx->fluid->x, ctx->fluid->y, ctx->fluid->z, ctx->nd, p, ap[0], ap[1], ap[2]);
    } else if (thermo) {
        nonpressure(ctx, noise, 1, 1, p, ap);
    } else {
        nonpressure(ctx, NULL, 0, 1, p, ap);
    }
}

/* ---- the stages this module owns ---- */

/* gravity and viscosity (with the thermostat's random forces, fused, when it is on) */
static int forces_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    (void)err;
    if (st->noise[0]) pfsph__nonpressure_thermo(st->ctx, st->noise);
    else pfsph__nonpressure(st->ctx);
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_forces = {.name = "forces",
                                            .slot = PFSPH_STAGE_FORCES,
                                            .reads = PFSPH_D_POS | PFSPH_D_VEL | PFSPH_D_DENSITY | PFSPH_D_DT,
                                            .writes = PFSPH_D_ACC | PFSPH_D_NOISE,
                                            .run = forces_run};

/* A solver whose pressure follows from the density alone (its eos), without pair forces (their
 * stage would sit between and read last step's pressure): the pressure and its acceleration in
 * the viscosity's walk, two walks a step instead of three, the same bits (solver.h, eos). */
static int forces_eos_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    (void)err;
    st->solver->eos(st->solver_state, st->ctx);
    pfsph__forces_and_pressure(st->ctx, st->noise[0] ? st->noise : NULL, st->ctx->fluid->p, st->ap);
    return PFSPH_OK;
}

const pfsph_stage_ops pfsph_stage_forces_eos = {.name = "forces",
                                                .slot = PFSPH_STAGE_FORCES,
                                                .reads = PFSPH_D_POS | PFSPH_D_VEL | PFSPH_D_DENSITY | PFSPH_D_DT,
                                                .writes = PFSPH_D_ACC | PFSPH_D_NOISE | PFSPH_D_PRESSURE | PFSPH_D_AP,
                                                .run = forces_eos_run};
