/* The fluid's forces on the body particles (pfsph_bodies_fluid_forces, bodies.h): the reactions
 * of the fluid's pressure, friction, thermostat and pair forces, summed per body into a force
 * and a torque about its centre of mass. */
#include "pfsph/bodies.h"
#include "pfsph/thermostat.h"

#include <math.h>
#include <string.h>

#include "pfsph/dist.h"
#include "physics/bodies_internal.h"

/* Whether this rank owns the fluid grid cell of boundary particle j (clamped into the grid). */
static bool owns(const pfsph_grid *g, const pfsph_dist *D, const pfsph_particles *b, size_t j)
{
    const size_t key = pfsph_grid_cell_clamped(g, b->x[j], b->y[j], b->z[j]);
    return key >= D->cell_lo && key < D->cell_hi;
}

void pfsph_bodies_fluid_forces(pfsph_bodies *B, const pfsph_ctx *ctx, const pfsph_real *p)
{
    const pfsph_kernel *k = &ctx->kern;
    const pfsph_particles *f = ctx->fluid, *b = ctx->boundary;
    const pfsph_real h2 = k->h * k->h, eps = (pfsph_real)0.01 * h2;
    const pfsph_real inv_v0 = (pfsph_real)1 / ctx->V0;
    const pfsph_real visc_c = (pfsph_real)(2 * (ctx->dim + 2));
    const uint32_t first = B->first_id;
    const size_t nb = b->n;
    const pfsph_pairwise_params *pp = ctx->pairwise;
    const bool pw_on = pp->enabled;
    const double Rk = pw_on ? pp->k * (double)ctx->h : 0, U_R = pw_on ? 1.5 * PI / Rk : 0;
    const pfsph_real R2 = (pfsph_real)(Rk * Rk);
    double cm[PFSPH_MAX_PHASES][PFSPH_MAX_PHASES]; /* c m_a m_b, once per call */
    for (int a = 0; pw_on && a < ctx->nphases; a++)
        for (int q = 0; q < ctx->nphases; q++) cm[a][q] = pp->c[a][q] * (double)ctx->mass[a] * (double)ctx->mass[q];
    /* particles dropped from the boundary set (a body that left the grid) must not keep their
     * last force: only the present ones are written below */
    memset(B->fp, 0, 3 * (size_t)B->np * sizeof(double));
    const double amp = pfsph__thermo_amp(ctx);
    const uint64_t wkey = pfsph_thermo_step_key(ctx->seed, ctx->step, PFSPH_THERMO_SALT_WALL);
    pfsph_dist *D = ctx->dist;
#pragma omp parallel for schedule(static)
    for (size_t j = 0; j < nb; j++) {
        if (b->id[j] < first) continue;
        const uint32_t l = b->id[j] - first;
        if (D && !owns(ctx->grid, D, b, j)) { /* another rank's: its fluid is there (below) */
            B->fp[3 * l] = B->fp[3 * l + 1] = B->fp[3 * l + 2] = -0.0;
            continue;
        }
        const pfsph_real xj = b->x[j], yj = b->y[j], zj = b->z[j], vol = b->aux[j];
        double fx = 0, fy = 0, fz = 0, tx = 0, ty = 0, tz = 0;
        pfsph_ranges r;
        pfsph_grid_ranges(ctx->grid, xj, yj, zj, &r);
        for (int q = 0; q < r.n; q++)
            for (uint32_t i = r.b[q]; i < r.e[q]; i++) {
                /* the same expressions, in the same order, as the fluid side, with x_ib */
                pfsph_real dx = f->x[i] - xj, dy = f->y[i] - yj, dz = f->z[i] - zj;
                pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                if (r2 >= h2) continue;
                pfsph_real dw = pfsph_kernel_dw_r(k, pfsph_sqrt(r2));
                pfsph_real s = 0;
                const pfsph_real pi = p[i] / (ctx->nd[i] * ctx->nd[i]);
                if (pi > 0) s += pi * inv_v0 * vol * dw; /* pressure: -F_i of Akinci Eq. 10 */
                const pfsph_real nui = ctx->nu[f->phase[i]];
                if (nui > 0) {
                    pfsph_real vdx =
                        (f->vx[i] - b->vx[j]) * dx + (f->vy[i] - b->vy[j]) * dy + (f->vz[i] - b->vz[j]) * dz;
                    /* friction: the fluid gains m_i nu visc_c V_b (v_ib . x_ib)/(r^2+eps) grad W */
                    s -= ctx->mass[f->phase[i]] * visc_c * nui * vol * vdx / (r2 + eps) * dw;
                    if (amp > 0 && r2 > 0) {
                        /* the thermostat's random force on the fluid, reversed (thermostat.c:
                         * the same expression, same draw) */
                        double rr = sqrt((double)r2);
                        /* x_ib points from the body particle to the fluid: -e_ib on the body */
                        double sr = -pfsph__thermo_wall(amp * pfsph_thermostat_scale(ctx, f->phase[i]), (double)nui,
                                                        (double)ctx->mass[f->phase[i]], (double)vol, (double)r2,
                                                        (double)pfsph_kernel_dw_r(k, (pfsph_real)rr), (double)eps, rr,
                                                        pfsph_thermo_theta(wkey, f->id[i], b->id[j]));
                        tx += sr * (double)dx;
                        ty += sr * (double)dy;
                        tz += sr * (double)dz;
                    }
                }
                fx += (double)(s * dx);
                fy += (double)(s * dy);
                fz += (double)(s * dz);
            }
        fx += tx;
        fy += ty;
        fz += tz;
        if (pw_on) {
            /* the pair forces' reaction (PF Eq. 3): -c m_i m_b f(r) x_ib / r, over k h. The
             * fluid applies its filter T_i (Eq. 12) to its own sum, so with eta > 0 action and
             * reaction differ by that filter; with eta = 0 they cancel exactly. */
            const int pb = b->phase[j];
            pfsph_grid_ranges_far(ctx->grid, xj, yj, zj, &r);
            for (int q = 0; q < r.n; q++)
                for (uint32_t i = r.b[q]; i < r.e[q]; i++) {
                    const double cf = cm[f->phase[i]][pb];
                    if (cf == 0.0) continue;
                    pfsph_real dx = f->x[i] - xj, dy = f->y[i] - yj, dz = f->z[i] - zj;
                    pfsph_real r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 >= R2 || r2 <= 0) continue;
                    double rr = sqrt((double)r2);
                    double sp = -cf * (double)cosf((float)(U_R * rr)) / rr;
                    fx += sp * dx;
                    fy += sp * dy;
                    fz += sp * dz;
                }
        }
        B->fp[3 * l] = fx;
        B->fp[3 * l + 1] = fy;
        B->fp[3 * l + 2] = fz;
    }
    /* distributed: each body particle's force from the rank that owns its cell, whose halo
     * holds every fluid particle its walks reach; -0.0 from the others adds nothing */
    if (D) D->allsum(D, B->fp, 3 * (size_t)B->np);
    /* sums in id order: the same bits for any thread count and particle order */
    for (int i = 0; i < B->nb; i++) {
        body *bd = &B->b[i];
        const dReal *Rm = dBodyGetRotation(bd->id);
        double F[3] = {0, 0, 0}, T[3] = {0, 0, 0};
        for (uint32_t l = bd->first; l < bd->first + bd->n; l++) {
            const double *fl = B->fp + 3 * l, *lc = B->local + 3 * l;
            double rr[3];
            for (int a = 0; a < 3; a++) rr[a] = Rm[4 * a] * lc[0] + Rm[4 * a + 1] * lc[1] + Rm[4 * a + 2] * lc[2];
            for (int a = 0; a < 3; a++) F[a] += fl[a];
            T[0] += rr[1] * fl[2] - rr[2] * fl[1];
            T[1] += rr[2] * fl[0] - rr[0] * fl[2];
            T[2] += rr[0] * fl[1] - rr[1] * fl[0];
        }
        if (B->dim == 2) F[2] = T[0] = T[1] = 0;
        memcpy(bd->f, F, sizeof F);
        memcpy(bd->tq, T, sizeof T);
    }
}
