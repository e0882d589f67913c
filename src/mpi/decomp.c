/* The domain decomposition: the fluid cut along the grid's cell order (row-major keys, the order
 * the serial sort leaves the particles in) into one contiguous range of cells per rank, by
 * measured cost (or particle count), re-cut every step; each rank holds its cells plus every
 * cell a neighbour walk from them can reach (a key interval), so its particles are a contiguous
 * slice of the serial order and every walk visits the same neighbours in the same order as a
 * serial run. */
#include "mpi/decomp.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <stdio.h>

#include "core/reduce.h"
#include "core/stage.h"
#include "mpi/wire.h"
#include "sim_internal.h"

/* The cell key of the serial sort (pfsph_grid_sort_in), UINT32_MAX for a particle it removes. */
static uint32_t cell_key(const pfsph_grid *g, const pfsph_particles *f, size_t i)
{
    const pfsph_real *pos[3] = {f->x, f->y, f->z};
    size_t lin = 0, stride = 1;
    for (int a = 0; a < g->dim; a++) {
        pfsph_real v = pos[a][i];
        if (!(v >= g->keep_lo[a] && v <= g->keep_hi[a] && v >= g->lo[a] && v <= g->hi[a])) return UINT32_MAX;
        int c = (int)((v - g->lo[a]) * g->inv_cell);
        if (c >= g->nc[a]) c = g->nc[a] - 1;
        lin += (size_t)c * stride;
        stride *= (size_t)g->nc[a];
    }
    return (uint32_t)lin;
}

/* What the root's state says after a start, a frame or a resume, for every rank. */
typedef struct clock_state {
    double time, amax, amax_np, vbound, dt, ctime;
    uint64_t step, cstep, removed;
    pfsph_step_stats stats;
} clock_state;

static void share_clock(pfsph_decomp *D, pfsph_step *st)
{
    clock_state s = {st->time,      st->amax, st->amax_np,   st->vbound,  st->ctx->dt,
                     st->ctx->time, st->step, st->ctx->step, st->removed, st->stats};
    MPI_Bcast(&s, sizeof s, MPI_BYTE, 0, D->comm);
    st->time = s.time;
    st->amax = s.amax;
    st->amax_np = s.amax_np;
    st->vbound = s.vbound;
    st->ctx->dt = s.dt;
    st->ctx->time = s.ctime;
    st->step = s.step;
    st->ctx->step = s.cstep;
    st->removed = (size_t)s.removed;
    st->stats = s.stats;
}

/* A resume: the root restored the bodies from the checkpoint; the others do the same with its
 * states and its boundary order (every rank keeps every wall with bodies). */
static int share_bodies(pfsph_decomp *D, pfsph_step *st, int nbod, pfsph_error *err)
{
    pfsph_particles *b = st->ctx->boundary;
    pfsph_body_state *bs = malloc((size_t)nbod * sizeof *bs);
    uint64_t n = b->n;
    MPI_Bcast(&n, 1, MPI_UINT64_T, 0, D->comm);
    uint32_t *ids = malloc((n ? n : 1) * sizeof(uint32_t));
    if (!bs || !ids) MPI_Abort(D->comm, 1);
    for (int i = 0; i < nbod; i++) pfsph_bodies_get_state(st->bodies, i, &bs[i]);
    if (D->rank == 0) memcpy(ids, b->id, n * sizeof(uint32_t));
    MPI_Bcast(bs, (int)((size_t)nbod * sizeof *bs), MPI_BYTE, 0, D->comm);
    MPI_Bcast(ids, (int)n, MPI_UINT32_T, 0, D->comm);
    int rc = D->rank ? pfsph_sim_restore_bodies(D->sim, nbod, bs, ids, (size_t)n, err) : PFSPH_OK;
    free(bs);
    free(ids);
    return rc;
}

/* Cells [lo, hi) rank q holds: its own and those within a walk's reach of them. */
static void held_cells(const pfsph_decomp *D, int q, size_t *lo, size_t *hi)
{
    *lo = D->cut[q] > D->off ? D->cut[q] - D->off : 0;
    *hi = D->cut[q + 1] + D->off < D->ncells ? D->cut[q + 1] + D->off : D->ncells;
}

/* A rank other than the root holds its slice alone: the whole scene's arrays it was created with
 * (every rank samples the scene) are cut down to the slice, so that its memory follows its share.
 * They grow again through the step's reserve if its slice grows. The root too when the frames
 * are written collectively (it gathers the fluid only for a checkpoint, and grows again then). */
static int fit(pfsph_decomp *D, pfsph_particles *f, size_t n)
{
    if ((D->rank == 0 && !pfsph_mpi_frames_collective(D)) || f->cap <= 2 * n + 4096) return PFSPH_OK;
    const size_t cap = n + n / 4 + 1024;
    for (int k = 0; k < PFSPH_NFIELDS; k++) {
        void *q = realloc(f->f[k], cap * sizeof(pfsph_real));
        if (!q) return PFSPH_ENOMEM;
        f->f[k] = q;
    }
    void *q;
    if (!(q = realloc(f->phase, cap))) return PFSPH_ENOMEM;
    f->phase = q;
    if (!(q = realloc(f->wall, cap))) return PFSPH_ENOMEM;
    f->wall = q;
    if (!(q = realloc(f->bubble, cap))) return PFSPH_ENOMEM;
    f->bubble = q;
    if (!(q = realloc(f->id, cap * sizeof(uint32_t)))) return PFSPH_ENOMEM;
    f->id = q;
    f->cap = cap;
    return pfsph__sim_alloc_scratch(D->sim, cap);
}

/* ---- static walls: a rank other than the root keeps those its slice's walks can reach ----
 * Every rank samples the whole scene; the walls are sorted once by cell (the boundary grid).
 * Rank q needs the walls of the cells within off of the cells it holds (twice a walk's reach
 * from its own). Each step every rank works out every rank's window the same way: when q's
 * need leaves its window, or the window is larger than a move would make it, the window becomes
 * the need widened by a quarter each side (PFSPH_MPI_WALL_SLACK, percent: the tests set 0 to move it
 * every step); inside the old window q cuts its arrays down itself, else the
 * root, which keeps every wall, sends the new window's walls (one contiguous run of its sorted
 * walls). Walks see the same walls in the same order as a serial run: byte-identical. */
static int walls_resize(pfsph_particles *b, size_t n)
{
    const size_t cap = n ? n : 1;
    for (int k = 0; k < PFSPH_NFIELDS; k++) {
        void *q = realloc(b->f[k], cap * sizeof(pfsph_real));
        if (!q) return PFSPH_ENOMEM;
        b->f[k] = q;
    }
    void *q;
    if (!(q = realloc(b->phase, cap))) return PFSPH_ENOMEM;
    b->phase = q;
    if (!(q = realloc(b->wall, cap))) return PFSPH_ENOMEM;
    b->wall = q;
    if (!(q = realloc(b->bubble, cap))) return PFSPH_ENOMEM;
    b->bubble = q;
    if (!(q = realloc(b->id, cap * sizeof(uint32_t)))) return PFSPH_ENOMEM;
    b->id = q;
    b->cap = cap;
    return PFSPH_OK;
}

static void wall_need(const pfsph_decomp *D, int q, size_t *lo, size_t *hi)
{
    size_t a, b;
    held_cells(D, q, &a, &b);
    *lo = a > D->off ? a - D->off : 0;
    *hi = b + D->off < D->ncells ? b + D->off : D->ncells;
}

static int walls_update(pfsph_decomp *D, pfsph_error *err)
{
    pfsph_ctx *c = &D->sim->ctx;
    pfsph_particles *b = c->boundary;
    uint32_t *st = c->bgrid->start;
    const size_t nc = D->ncells;
    int rc = PFSPH_OK;
    for (int q = 1; q < D->size; q++) {
        size_t lo, hi;
        wall_need(D, q, &lo, &hi);
        const size_t wlo = D->wlo[q], whi = D->whi[q], s = (hi - lo) * D->wall_slack / 100;
        const int inside = lo >= wlo && hi <= whi;
        if (inside && whi - wlo <= hi - lo + 2 * s + 2) continue; /* no larger than a move would make it */
        size_t nlo = lo > s ? lo - s : 0, nhi = hi + s < nc ? hi + s : nc;
        if (inside) { /* a cut within the walls q has: no more than those */
            if (nlo < wlo) nlo = wlo;
            if (nhi > whi) nhi = whi;
        }
        D->wlo[q] = nlo;
        D->whi[q] = nhi;
        if (inside) { /* q cuts its own arrays down */
            if (q != D->rank) continue;
            const size_t i0 = st[nlo], cnt = st[nhi] - i0;
            for (int k = 0; k < PFSPH_NFIELDS; k++) memmove(b->f[k], b->f[k] + i0, cnt * sizeof(pfsph_real));
            memmove(b->phase, b->phase + i0, cnt);
            memmove(b->wall, b->wall + i0, cnt);
            memmove(b->bubble, b->bubble + i0, cnt);
            memmove(b->id, b->id + i0, cnt * sizeof(uint32_t));
            for (size_t k = nlo; k <= nhi; k++) st[k] -= (uint32_t)i0;
            for (size_t k = 0; k < nlo; k++) st[k] = 0;
            for (size_t k = nhi + 1; k <= nc; k++) st[k] = (uint32_t)cnt;
            b->n = cnt;
            if (walls_resize(b, cnt)) rc = PFSPH_ENOMEM; /* a shrink: cannot fail in practice */
            D->wall_trims++;
        } else if (D->rank == 0) { /* the root sends the window's walls */
            const size_t i0 = st[nlo], cnt = st[nhi] - i0;
            if (cnt * REC > (size_t)INT32_MAX || grow(&D->sbuf, &D->scap, cnt * REC)) MPI_Abort(D->comm, 1);
            for (size_t i = 0; i < cnt; i++) pack(D->sbuf + i * REC, b, NULL, i0 + i);
            MPI_Send(D->sbuf, (int)(cnt * REC), MPI_BYTE, q, 29, D->comm);
            D->wall_bytes += cnt * REC;
        } else if (q == D->rank) {
            MPI_Status ms;
            int bytes;
            MPI_Probe(0, 29, D->comm, &ms);
            MPI_Get_count(&ms, MPI_BYTE, &bytes);
            if (grow(&D->rbuf, &D->rcap, (size_t)bytes)) MPI_Abort(D->comm, 1);
            MPI_Recv(D->rbuf, bytes, MPI_BYTE, 0, 29, D->comm, MPI_STATUS_IGNORE);
            const size_t cnt = (size_t)bytes / REC;
            if (walls_resize(b, cnt)) MPI_Abort(D->comm, 1);
            memset(st, 0, (nc + 1) * sizeof(uint32_t));
            for (size_t i = 0; i < cnt; i++) {
                unpack(D->rbuf + i * REC, b, NULL, i);
                st[cell_key(c->bgrid, b, i) + 1]++;
            }
            for (size_t k = 0; k < nc; k++) st[k + 1] += st[k];
            b->n = cnt;
            D->wall_fetches++;
        }
    }
    if (D->rank && b->n > D->walls_max) D->walls_max = b->n;
    if (rc) return pfsph_fail(err, rc, "out of memory cutting the walls down");
    return PFSPH_OK;
}

/* PFSPH_MPI_CHECK_CUT=1 (the tests): every step's cut against the dense histogram's */
static int check_cut(pfsph_decomp *D, const uint32_t *key, size_t m, pfsph_error *err)
{
    pfsph_cut E;
    if (pfsph_cut_init(&E, D->size, 1)) MPI_Abort(D->comm, 1); /* a check's allocation */
    pfsph_cut_dense(&E, D->comm, key, m, D->ncells, D->off, D->cost.weight);
    int bad = E.removed != D->C.removed || E.total != D->C.total;
    for (int q = 0; q <= D->size; q++) bad |= E.cut[q] != D->cut[q] || E.gofs[q] != D->gofs[q];
    for (int q = 0; q < D->size; q++) bad |= E.lofs[q] != D->lofs[q] || E.lend[q] != D->lend[q];
    pfsph_cut_free(&E);
    if (bad)
        return pfsph_fail(err, PFSPH_EIO, "the sparse cut differs from the dense histogram's at step %llu",
                          (unsigned long long)D->steps);
    D->cuts_checked++;
    return PFSPH_OK;
}

/* Every step but the first: each rank sends each particle it owns, rank by rank, each in its
 * order, to every rank that holds its new cell (one Alltoallv); n: the particles received. */
static int exchange_slices(pfsph_decomp *D, pfsph_step *st, const uint32_t *key, size_t lo, size_t m, size_t *out,
                           pfsph_error *err)
{
    pfsph_particles *f = st->ctx->fluid;
    int q, rc;
    size_t n;
    /* pack, rank by rank, each in this rank's order */
    size_t bytes = 0;
    for (q = 0; q < D->size; q++) {
        size_t a, b, cnt = 0;
        held_cells(D, q, &a, &b);
        for (size_t i = 0; i < m; i++) cnt += key[i] >= a && key[i] < b;
        D->scount[q] = (int)(cnt * REC);
        D->sdispl[q] = (int)bytes;
        bytes += cnt * REC;
    }
    if (bytes > (size_t)INT32_MAX || grow(&D->sbuf, &D->scap, bytes))
        return pfsph_fail(err, PFSPH_ENOMEM, "exchange: %zu bytes to send (at most 2 GiB a step)", bytes);
    for (q = 0; q < D->size; q++) {
        size_t a, b;
        held_cells(D, q, &a, &b);
        char *o = D->sbuf + D->sdispl[q];
        for (size_t i = 0; i < m; i++)
            if (key[i] >= a && key[i] < b) {
                pack(o, f, NULL, lo + i);
                o += REC;
            }
    }
    MPI_Alltoall(D->scount, 1, MPI_INT, D->rcount, 1, MPI_INT, D->comm);
    size_t rbytes = 0;
    for (q = 0; q < D->size; q++) {
        D->rdispl[q] = (int)rbytes;
        rbytes += (size_t)D->rcount[q];
    }
    if (grow(&D->rbuf, &D->rcap, rbytes)) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory for the exchange");
    MPI_Alltoallv(D->sbuf, D->scount, D->sdispl, MPI_BYTE, D->rbuf, D->rcount, D->rdispl, MPI_BYTE, D->comm);
    n = rbytes / REC;
    if (n != D->lend[D->rank] - D->lofs[D->rank])
        return pfsph_fail(err, PFSPH_EIO, "exchange: rank %d received %zu particles for a slice of %llu", D->rank, n,
                          (unsigned long long)(D->lend[D->rank] - D->lofs[D->rank]));
    rc = st->reserve(st, n, err);
    if (!rc && fit(D, f, n)) rc = pfsph_fail(err, PFSPH_ENOMEM, "out of memory fitting the slice's arrays");
    if (rc) return rc;
    for (size_t i = 0; i < n; i++) unpack(D->rbuf + i * REC, f, NULL, i);
    *out = n;
    return PFSPH_OK;
}

/* A start or a resume: the root alone holds every particle. It sends each other rank its
 * slice in runs of GATHER_RUN particles through one bounded buffer (no copy of the whole
 * fluid), then keeps its own in place, in its order: what the Alltoallv would give. */
static int scatter_root(pfsph_decomp *D, pfsph_step *st, const uint32_t *key, size_t m, size_t *out, pfsph_error *err)
{
    pfsph_particles *f = st->ctx->fluid;
    const size_t n = (size_t)(D->lend[D->rank] - D->lofs[D->rank]);
    for (int q = 0; q < D->size; q++) D->scount[q] = 0;
    if (D->rank == 0) {
        if (grow(&D->sbuf, &D->scap, GATHER_RUN * REC)) MPI_Abort(D->comm, 1); /* the others wait */
        for (int q = 1; q < D->size; q++) {
            size_t a, b, k = 0, sent = 0;
            held_cells(D, q, &a, &b);
            for (size_t i = 0; i <= m; i++) {
                if (i < m && key[i] >= a && key[i] < b) pack(D->sbuf + k++ * REC, f, NULL, i);
                if (k == GATHER_RUN || (i == m && k)) {
                    MPI_Send(D->sbuf, (int)(k * REC), MPI_BYTE, q, 31, D->comm);
                    sent += k;
                    k = 0;
                }
            }
            D->scount[q] = (int)(sent * REC);
        }
        size_t a, b, k = 0;
        held_cells(D, 0, &a, &b);
        for (size_t i = 0; i < m; i++)
            if (key[i] >= a && key[i] < b) {
                if (k != i) {
                    for (int j = 0; j < PFSPH_NFIELDS; j++) f->f[j][k] = f->f[j][i];
                    f->id[k] = f->id[i];
                    f->phase[k] = f->phase[i];
                    f->wall[k] = f->wall[i];
                    f->bubble[k] = f->bubble[i];
                }
                k++;
            }
        if (k != n) MPI_Abort(D->comm, 1); /* the cut's count and the keys disagree: a bug */
    } else {
        int rc = st->reserve(st, n, err);
        if (!rc && fit(D, f, n)) rc = PFSPH_ENOMEM;
        if (rc || grow(&D->rbuf, &D->rcap, GATHER_RUN * REC)) MPI_Abort(D->comm, 1); /* the root is sending */
        for (size_t o = 0; o < n; o += GATHER_RUN) {
            const size_t k = n - o < GATHER_RUN ? n - o : GATHER_RUN;
            MPI_Recv(D->rbuf, (int)(k * REC), MPI_BYTE, 0, 31, D->comm, MPI_STATUS_IGNORE);
            for (size_t i = 0; i < k; i++) unpack(D->rbuf + i * REC, f, NULL, o + i);
        }
    }
    (void)err;
    *out = n;
    return PFSPH_OK;
}

/* The stage before the grid sort: the particles each rank owned (all on the root after a
 * frame) go to every rank that holds their new cell. Each rank sends its particles in its
 * order, the receivers take them in rank order, so the grid's stable sort then gives them the
 * serial order: by cell, ties by the previous step's order. */
static int exchange_body(pfsph_decomp *D, pfsph_step *st, pfsph_error *err)
{
    pfsph_ctx *c = st->ctx;
    pfsph_particles *f = c->fluid;
    const pfsph_grid *g = c->grid;
    if (D->gathered || D->framed) { /* after a frame: the root's own slice again, the clock as the root has it */
        if (D->gathered && D->rank == 0) f->n = D->lend[0], D->d.own_lo = 0, D->d.own_hi = D->root_own_hi;
        D->gathered = D->framed = 0;
        share_clock(D, st);
    }
    if (D->share) { /* a start or a resume: the root's clock and state */
        share_clock(D, st);
        if (st->df) { /* a resume: the diffuse totals the root restored (the ids go on from them) */
            size_t *nold;
            uint64_t *cr, *rf;
            pfsph_particles *ds = pfsph__diffuse_set(st->df, &nold, &cr, &rf);
            uint64_t v[3] = {*cr, *rf, ds->next_id};
            MPI_Bcast(v, 3, MPI_UINT64_T, 0, D->comm);
            *cr = v[0];
            *rf = v[1];
            ds->next_id = (uint32_t)v[2];
        }
        /* a resume: the bodies' state and the order of the boundary particles the root restored */
        const int nbod = pfsph_bodies_count(st->bodies);
        int brc;
        if (nbod && st->step > 0 && (brc = share_bodies(D, st, nbod, err))) return brc;
        /* a resume: the ids the emitters go on from, and their state */
        MPI_Bcast(&f->next_id, 1, MPI_UINT32_T, 0, D->comm);
        for (int i = 0; i < pfsph_emitters_count(st->em); i++) {
            pfsph_emitter_state es;
            pfsph_emitters_get_state(st->em, i, &es);
            MPI_Bcast(&es, sizeof es, MPI_BYTE, 0, D->comm);
            if (pfsph_emitters_set_state(st->em, i, &es, st->time, err)) return PFSPH_EINPUT; /* the root's own */
        }
    }
    size_t lo = D->root_all ? 0 : D->d.own_lo, hi = D->root_all ? (D->rank == 0 ? f->n : 0) : D->d.own_hi;
    const size_t m = hi - lo, nc = D->ncells;
    int rc;
    uint32_t *key = realloc(D->key, (m ? m : 1) * sizeof(uint32_t));
    if (!key) return pfsph_fail(err, PFSPH_ENOMEM, "out of memory for the exchange's keys");
    D->key = key;
    for (size_t i = 0; i < m; i++) key[i] = cell_key(g, f, lo + i);
    if (pfsph_cut_compute(&D->C, D->comm, key, m, nc, D->off, D->cost.weight))
        return pfsph_fail(err, PFSPH_ENOMEM, "out of memory for the cut"); /* every rank returns it */
    if (D->check_cut && (rc = check_cut(D, key, m, err))) return rc;
    if (D->trim_walls && (rc = walls_update(D, err))) return rc;
    const uint64_t total = D->C.total;
    int q;
    size_t n = 0;
    rc = D->root_all ? scatter_root(D, st, key, m, &n, err) : exchange_slices(D, st, key, lo, m, &n, err);
    if (rc) return rc;
    f->n = n;
    if (n + c->boundary->n > D->resident_max) D->resident_max = n + c->boundary->n;
    /* particles that left the domain: counted once, and the speed the next step's CFL needs is
     * then the largest of those that stay (the serial grid and timestep stages) */
    if (D->C.removed) {
        st->removed += D->C.removed;
        size_t worst;
        double v = n ? pfsph__max_speed(f, &worst) : 0;
        MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_MAX, D->comm);
        st->stats.vmax = v;
    }
    D->d.own_lo = (size_t)(D->gofs[D->rank] - D->lofs[D->rank]);
    D->d.own_hi = (size_t)(D->gofs[D->rank + 1] - D->lofs[D->rank]);
    D->own_g0 = D->gofs[D->rank];
    D->d.nglobal = (size_t)total;
    D->d.cell_lo = D->cut[D->rank];
    D->d.cell_hi = D->cut[D->rank + 1];
    D->root_all = 0;
    D->share = 0;
    D->d.fluid_whole = 0;
    /* figures */
    const size_t own = D->d.own_hi - D->d.own_lo;
    if (!D->steps || own < D->own_min) D->own_min = own;
    if (own > D->own_max) D->own_max = own;
    D->steps++;
    D->halo_particles += n - own;
    for (q = 0; q < D->size; q++)
        if (q != D->rank && D->scount[q]) {
            D->migr_bytes += (uint64_t)D->scount[q];
            D->messages++;
        }
    D->cost.weighted_cuts += D->C.weighted;
    return PFSPH_OK;
}

/* The exchange is the decomposition's: it closes the last step's measured work (the first step
 * after a start or a resume scattered the fluid and touched fresh memory: not measured) */
static int exchange_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)bad;
    pfsph_decomp *D = state;
    pfsph_cost_enter(D);
    pfsph_cost_sample(D, D->steps < 2);
    const int rc = exchange_body(D, st, err);
    D->cost.own = D->d.own_hi - D->d.own_lo;
    pfsph_cost_leave(D);
    return rc;
}

static const pfsph_stage_ops stage_exchange = {.name = "mpi_exchange",
                                               .slot = PFSPH_STAGE_GRID,
                                               .reads = PFSPH_D_POS | PFSPH_D_VEL,
                                               .writes = PFSPH_D_ORDER | PFSPH_D_POS | PFSPH_D_VEL | PFSPH_D_STATS,
                                               .run = exchange_run};

/* The halo copies of n arrays refreshed from their owners: rank q sends what it owns of the
 * slice rank r holds, a contiguous range of the serial order on both sides. */
static void halo(pfsph_dist *d, pfsph_real *const *a, int k)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    const int r = D->rank;
    const size_t rs = sizeof(pfsph_real);
    size_t bytes = 0, rbytes = 0;
    size_t *s_lo = D->qa, *r_lo = D->qb;
    for (int q = 0; q < D->size; q++) {
        uint64_t s = D->gofs[r] > D->lofs[q] ? D->gofs[r] : D->lofs[q];
        uint64_t e = D->gofs[r + 1] < D->lend[q] ? D->gofs[r + 1] : D->lend[q];
        uint64_t s2 = D->gofs[q] > D->lofs[r] ? D->gofs[q] : D->lofs[r];
        uint64_t e2 = D->gofs[q + 1] < D->lend[r] ? D->gofs[q + 1] : D->lend[r];
        size_t ns = q != r && e > s ? (size_t)(e - s) : 0, nr = q != r && e2 > s2 ? (size_t)(e2 - s2) : 0;
        s_lo[q] = s - D->lofs[r];
        r_lo[q] = s2 - D->lofs[r];
        D->scount[q] = (int)(ns * (size_t)k * rs);
        D->sdispl[q] = (int)bytes;
        D->rcount[q] = (int)(nr * (size_t)k * rs);
        D->rdispl[q] = (int)rbytes;
        bytes += (size_t)D->scount[q];
        rbytes += (size_t)D->rcount[q];
    }
    if (grow(&D->sbuf, &D->scap, bytes) || grow(&D->rbuf, &D->rcap, rbytes)) MPI_Abort(D->comm, 1);
    for (int q = 0; q < D->size; q++) {
        const size_t ns = (size_t)D->scount[q] / ((size_t)k * rs);
        for (int j = 0; j < k; j++) memcpy(D->sbuf + D->sdispl[q] + (size_t)j * ns * rs, a[j] + s_lo[q], ns * rs);
        if (q != r && ns) {
            D->messages++;
            D->bytes_sent += (uint64_t)D->scount[q];
        }
    }
    MPI_Alltoallv(D->sbuf, D->scount, D->sdispl, MPI_BYTE, D->rbuf, D->rcount, D->rdispl, MPI_BYTE, D->comm);
    for (int q = 0; q < D->size; q++) {
        const size_t nr = (size_t)D->rcount[q] / ((size_t)k * rs);
        for (int j = 0; j < k; j++) memcpy(a[j] + r_lo[q], D->rbuf + D->rdispl[q] + (size_t)j * nr * rs, nr * rs);
    }
    D->halo_calls++;
}

/* ---- the serial pfsph__sum on any rank count ----
 * pfsph__sum adds blocks of PFSPH_SUM_BLOCK values from 0 in index order, then the blocks'
 * sums in order. A rank sends, for each block its owned range touches, the block's sum when it
 * holds all of it and its values otherwise; the root adds them exactly as the serial code. */
static size_t sum_msg(const pfsph_real *a, uint64_t G, uint64_t m, uint64_t N, double *out)
{
    const uint64_t B = PFSPH_SUM_BLOCK;
    size_t k = 0;
    if (!m) return 0;
    for (uint64_t b = G / B; b * B < G + m; b++) {
        uint64_t blo = b * B, bhi = blo + B < N ? blo + B : N, lo = G > blo ? G : blo, hi = G + m < bhi ? G + m : bhi;
        if (lo == blo && hi == bhi) {
            if (out) {
                double s = 0;
                for (uint64_t i = lo; i < hi; i++) s += (double)a[i - G];
                out[k] = s;
            }
            k++;
        } else {
            for (uint64_t i = lo; i < hi; i++, k++)
                if (out) out[k] = (double)a[i - G];
        }
    }
    return k;
}

static double sum(pfsph_dist *d, const pfsph_real *a)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    const uint64_t N = D->d.nglobal, B = PFSPH_SUM_BLOCK;
    const int r = D->rank;
    size_t tot = 0;
    for (int q = 0; q < D->size; q++) {
        size_t len = sum_msg(NULL, D->gofs[q], D->gofs[q + 1] - D->gofs[q], N, NULL);
        D->rcount[q] = (int)len;
        D->rdispl[q] = (int)tot;
        tot += len;
    }
    if (grow(&D->sbuf, &D->scap, (size_t)D->rcount[r] * sizeof(double)) ||
        (r == 0 && grow(&D->rbuf, &D->rcap, tot * sizeof(double))))
        MPI_Abort(D->comm, 1);
    double *mine = (double *)(void *)D->sbuf, *all = (double *)(void *)D->rbuf;
    sum_msg(a + D->d.own_lo, D->gofs[r], D->gofs[r + 1] - D->gofs[r], N, mine);
    MPI_Gatherv(mine, D->rcount[r], MPI_DOUBLE, all, D->rcount, D->rdispl, MPI_DOUBLE, 0, D->comm);
    double total = 0;
    if (r == 0) {
        size_t *pos = D->qa;
        for (int q = 0; q < D->size; q++) pos[q] = (size_t)D->rdispl[q];
        for (uint64_t b = 0; b * B < N; b++) {
            const uint64_t blo = b * B, bhi = blo + B < N ? blo + B : N;
            double s = 0;
            for (int q = 0; q < D->size; q++) {
                const uint64_t G = D->gofs[q], E = D->gofs[q + 1];
                const uint64_t lo = G > blo ? G : blo, hi = E < bhi ? E : bhi;
                if (lo >= hi) continue;
                if (lo == blo && hi == bhi) s += all[pos[q]++];
                else
                    for (uint64_t i = lo; i < hi; i++) s += all[pos[q]++];
            }
            total += s;
        }
    }
    MPI_Bcast(&total, 1, MPI_DOUBLE, 0, D->comm);
    return total;
}

/* ---- the stages between the physics' own ---- */

static int halo_pos_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    (void)err;
    pfsph_particles *f = st->ctx->fluid;
    pfsph_real *const a[3] = {f->x, f->y, f->z};
    st->ctx->dist->halo(st->ctx->dist, a, 3); /* timed as the decomposition's (cost.c) */
    return PFSPH_OK;
}

static const pfsph_stage_ops stage_halo_pos = {.name = "mpi_halo_positions",
                                               .slot = PFSPH_STAGE_GRID,
                                               .reads = PFSPH_D_POS,
                                               .writes = PFSPH_D_POS,
                                               .run = halo_pos_run};

static int halo_density_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)state;
    (void)bad;
    (void)err;
    pfsph_real *const a[1] = {st->ctx->nd};
    st->ctx->dist->halo(st->ctx->dist, a, 1);
    return PFSPH_OK;
}

static const pfsph_stage_ops stage_halo_density = {.name = "mpi_halo_density",
                                                   .slot = PFSPH_STAGE_DENSITY,
                                                   .reads = PFSPH_D_DENSITY,
                                                   .writes = PFSPH_D_DENSITY,
                                                   .run = halo_density_run};

/* the integration measured its own particles: the bounds the next step's time step needs; with
 * them the largest cost per particle, which scales each rank's weight at the next cut */
static int stats_run(void *state, pfsph_step *st, pfsph_blowup *bad, pfsph_error *err)
{
    (void)bad;
    (void)err;
    pfsph_decomp *D = state;
    pfsph_cost_enter(D);
    double v[5] = {st->amax, st->amax_np, st->stats.density_err_max, st->stats.vmax, pfsph_cost_local(D)};
    MPI_Allreduce(MPI_IN_PLACE, v, 5, MPI_DOUBLE, MPI_MAX, D->comm);
    st->amax = v[0];
    st->amax_np = v[1];
    st->stats.density_err_max = v[2];
    st->stats.vmax = v[3];
    pfsph_cost_weigh(D, v[4]);
    pfsph_cost_leave(D);
    return PFSPH_OK;
}

static const pfsph_stage_ops stage_stats = {.name = "mpi_stats",
                                            .slot = PFSPH_STAGE_INTEGRATE,
                                            .reads = PFSPH_D_STATS,
                                            .writes = PFSPH_D_STATS,
                                            .run = stats_run};

/* ---- the hooks the simulation calls ---- */

int pfsph_decomp_first_failure(pfsph_decomp *D, int rc, pfsph_error *err)
{
    int mine = rc ? D->rank : D->size, first;
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, D->comm);
    if (first == D->size) return PFSPH_OK;
    struct {
        int rc;
        pfsph_error e;
    } m;
    memset(&m, 0, sizeof m);
    if (D->rank == first) {
        m.rc = rc;
        if (err) m.e = *err;
    }
    MPI_Bcast(&m, sizeof m, MPI_BYTE, first, D->comm);
    if (err) *err = m.e;
    return m.rc;
}

static int agree(pfsph_dist *d, int rc, pfsph_error *err)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    rc = pfsph_decomp_first_failure(D, rc, err);
    if (rc) D->failed = 1; /* the run ends: the other ranks leave their command loop */
    return rc;
}

static void step_begin(pfsph_dist *d, double t_limit)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    if (D->rank != 0) return; /* the others are in their command loop */
    pfsph_mpi_cmd c = {PFSPH_MPI_STEP, 0, t_limit};
    pfsph_decomp_cmd(D, &c);
}

static int frame(pfsph_dist *d, pfsph_error *err)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    if (D->rank == 0) {
        pfsph_mpi_cmd c = {PFSPH_MPI_FRAME, 0, 0};
        pfsph_decomp_cmd(D, &c);
    }
    return pfsph_decomp_frame(D, err);
}

/* The root's side of a gather asked for after a collective frame (a checkpoint's). */
static int gather_now(pfsph_dist *d, pfsph_error *err)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    if (D->root_all || D->gathered) return PFSPH_OK;
    pfsph_mpi_cmd c = {PFSPH_MPI_GATHER, 0, 0};
    pfsph_decomp_cmd(D, &c);
    return pfsph_decomp_gather(D, err);
}

/* what ran since the decomposition's code was last left (the root's frame writing, the others'
 * wait for the command) is no step's work */
void pfsph_decomp_cmd(pfsph_decomp *D, pfsph_mpi_cmd *c)
{
    pfsph_cost_drop(D);
    pfsph_cost_enter(D);
    MPI_Bcast(c, sizeof *c, MPI_BYTE, 0, D->comm);
    pfsph_cost_leave(D);
}

static int attach(pfsph_dist *d, pfsph_sim *sim, pfsph_error *err);

int pfsph_decomp_init(pfsph_decomp *D, MPI_Comm comm)
{
    memset(D, 0, sizeof *D);
    D->comm = comm;
    MPI_Comm_rank(comm, &D->rank);
    MPI_Comm_size(comm, &D->size);
    const size_t P = (size_t)D->size;
    const char *b = getenv("PFSPH_MPI_CUT_BUCKETS"), *chk = getenv("PFSPH_MPI_CHECK_CUT");
    D->check_cut = chk && atoi(chk) > 0;
    if (pfsph_cut_init(&D->C, D->size, b && atoll(b) > 0 ? (uint64_t)atoll(b) : 0)) return PFSPH_ENOMEM;
    D->cut = D->C.cut;
    D->gofs = D->C.gofs;
    D->lofs = D->C.lofs;
    D->lend = D->C.lend;
    D->scount = calloc(P, sizeof(int));
    D->sdispl = calloc(P, sizeof(int));
    D->rcount = calloc(P, sizeof(int));
    D->rdispl = calloc(P, sizeof(int));
    D->wlo = calloc(P, sizeof(size_t));
    D->whi = calloc(P, sizeof(size_t));
    D->fig = calloc(P, sizeof(pfsph_mpi_fig));
    D->qa = calloc(P, sizeof(size_t));
    D->qb = calloc(P, sizeof(size_t));
    D->qc = calloc(P, sizeof(size_t));
    D->cnt2 = calloc(2 * P, sizeof(int));
    D->rcnt2 = calloc(2 * P, sizeof(int));
    D->scan_all = calloc(8 * P, sizeof(uint64_t));
    if (!D->scount || !D->sdispl || !D->rcount || !D->rdispl || !D->wlo || !D->whi || !D->fig || !D->qa || !D->qb ||
        !D->qc || !D->cnt2 || !D->rcnt2 || !D->scan_all)
        return PFSPH_ENOMEM;
    D->d.halo = halo;
    D->d.sum = sum;
    pfsph_decomp_set_hooks(D);  /* src/mpi/sets.c */
    pfsph_decomp_ckpt_hooks(D); /* src/mpi/ckpt.c */
    D->d.rank = D->rank;
    D->d.nranks = D->size;
    D->d.agree = agree;
    D->d.step_begin = step_begin;
    D->d.frame = frame;
    D->d.gather = gather_now;
    D->d.write_fluid = pfsph_mpi_write_fluid; /* src/mpi/frame_io.c */
    D->d.attach = attach;
    return pfsph_cost_init(D); /* times the hooks above */
}

/* Take the simulation over: the stages, the cut's arrays; the root holds every particle. */
static int attach(pfsph_dist *d, pfsph_sim *sim, pfsph_error *err)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    if (D->rank == 0) { /* the others create theirs from the same scene */
        pfsph_mpi_cmd c = {PFSPH_MPI_CREATE, 0, 0};
        pfsph_decomp_cmd(D, &c);
    }
    D->sim = sim;
    sim->ctx.dist = d;
    const pfsph_grid *g = &sim->grid;
    D->ncells = g->ncells;
    /* a walk from a particle moved since the sort (shifting, PCISPH's predicted positions) may
     * start one cell away: reach + 1 cells each way */
    const size_t R = (size_t)(g->reach_far > g->reach ? g->reach_far : g->reach) + 1;
    const size_t nx = (size_t)g->nc[0], ny = (size_t)g->nc[1];
    D->off = R * (1 + nx + (g->dim == 3 ? nx * ny : 0));
    int rc = pfsph_sim_insert_stage(sim, "grid", 0, &stage_exchange, D, err);
    if (!rc) rc = pfsph_sim_insert_stage(sim, "density", 1, &stage_halo_density, D, err);
    if (!rc) rc = pfsph_sim_insert_stage(sim, "integrate", 1, &stage_stats, D, err);
    if (!rc && sim->st.pw) rc = pfsph_sim_insert_stage(sim, "shift", 1, &stage_halo_pos, D, err);
    /* every rank holds every wall after the set-up; PFSPH_MPI_WALLS=all keeps them so */
    const char *wv = getenv("PFSPH_MPI_WALLS");
    D->trim_walls = !(wv && !strcmp(wv, "all")) && !sim->scene.nbodies;
    for (int q = 0; q < D->size; q++) D->wlo[q] = 0, D->whi[q] = D->ncells;
    const char *sl = getenv("PFSPH_MPI_WALL_SLACK");
    D->wall_slack = sl && atoi(sl) >= 0 ? (size_t)atoi(sl) : 25;
    D->walls_total = sim->boundary.n;
    D->root_all = 1;
    D->share = 1;
    D->d.fluid_whole = 1;
    D->d.own_lo = 0;
    D->d.own_hi = D->rank == 0 ? sim->fluid.n : 0;
    D->d.nglobal = sim->fluid.n;
    /* every rank built the simulation, or none goes on */
    return agree(d, rc, err);
}
