/* Checkpoints written and read by every rank with MPI-IO (docs/checkpoints.md, "Under MPI"):
 * the serial file's bytes, each rank its contiguous part of the fluid's arrays; the root the
 * header, the head and the tail (src/io/checkpoint_encode.c lays them out). */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

#include "io/checkpoint_format.h"
#include "io/io_internal.h"
#include "mpi/decomp.h"
#include "sim_internal.h"

/* bytes per MPI-IO call (its count is an int); a multiple of every element size */
#define CHUNK ((size_t)1 << 30)
/* on a big-endian host the arrays go through a staging buffer of this size, byte-swapped */
#define STAGE ((size_t)1 << 22)

/* This rank's part of the fluid in the serial order: local index *l0, global *g0, *m of them.
 * At the start the root holds all; after a frame's gather the root's own part is still at the
 * front of its arrays and every other rank's slice where it was. */
static void my_part(const pfsph_decomp *D, size_t *l0, uint64_t *g0, size_t *m)
{
    if (D->root_all) {
        *l0 = 0, *g0 = 0, *m = D->rank == 0 ? D->sim->ctx.fluid->n : 0;
    } else if (D->gathered && D->rank == 0) {
        *l0 = 0, *g0 = 0, *m = D->root_own_hi;
    } else {
        *l0 = D->d.own_lo, *g0 = D->own_g0, *m = D->d.own_hi - D->d.own_lo;
    }
}

/* a string from the root to every rank (malloc'ed on the others) */
static char *share_str(pfsph_decomp *D, const char *s)
{
    uint64_t n = D->rank == 0 ? strlen(s) + 1 : 0;
    MPI_Bcast(&n, 1, MPI_UINT64_T, 0, D->comm);
    char *c = malloc(n);
    if (!c) MPI_Abort(D->comm, 1);
    if (D->rank == 0) memcpy(c, s, n);
    MPI_Bcast(c, (int)n, MPI_CHAR, 0, D->comm);
    return c;
}

typedef struct isink {
    MPI_File fh;
    MPI_Offset off;
} isink;

/* the root's independent writes of the head and the tail */
static int file_sink(void *user, const void *p, size_t n)
{
    isink *s = user;
    while (n) {
        const size_t k = n > CHUNK ? CHUNK : n;
        if (MPI_File_write_at(s->fh, s->off, p, (int)k, MPI_BYTE, MPI_STATUS_IGNORE) != MPI_SUCCESS) return EIO;
        s->off += (MPI_Offset)k;
        p = (const char *)p + k;
        n -= k;
    }
    return 0;
}

/* the CRC32 of n bytes (zlib takes uInt lengths) */
static uint32_t crc_of(uint32_t crc, const unsigned char *p, size_t n)
{
    while (n) {
        const size_t k = n > CHUNK ? CHUNK : n;
        crc = (uint32_t)crc32(crc, p, (uInt)k);
        p += k;
        n -= k;
    }
    return crc;
}

/* Array k of the part [l0, l0 + m) to file offset off, every rank in the same number of
 * collective calls; the CRC32 of its bytes. */
static int write_array(pfsph_decomp *D, MPI_File fh, MPI_Offset off, int k, size_t l0, size_t m, size_t mmax,
                       unsigned char *stage, uint32_t *crc)
{
    const void *p;
    const size_t es = pfsph__checkpoint_array(D->sim->ctx.fluid, k, l0, &p);
    const int swap = !pfsph__host_le() && es > 1;
    const size_t piece = swap ? STAGE : CHUNK, bytes = m * es, rounds = (mmax * es + piece - 1) / piece;
    int bad = 0;
    *crc = (uint32_t)crc32(0L, Z_NULL, 0);
    for (size_t r = 0; r < (rounds ? rounds : 1); r++) {
        const size_t a = r * piece < bytes ? r * piece : bytes, b = a + piece < bytes ? a + piece : bytes;
        const unsigned char *src = (const unsigned char *)p + a;
        if (swap) {
            for (size_t i = 0; i < (b - a) / es; i++) pfsph__put_le(stage + i * es, src + i * es, es);
            src = stage;
        }
        *crc = crc_of(*crc, src, b - a);
        if (MPI_File_write_at_all(fh, off + (MPI_Offset)a, src, (int)(b - a), MPI_BYTE, MPI_STATUS_IGNORE) !=
            MPI_SUCCESS)
            bad = 1;
    }
    return bad;
}

/* per rank, gathered by the root: its particle count and the CRC32 of its part of each array */
typedef struct part_crc {
    uint64_t m;
    uint32_t crc[PFSPH__CKPT_ARRAYS];
} part_crc;

/* The root combines the ranks' CRC32s in the file's order: array by array, rank by rank. */
static uint32_t combine(const pfsph_decomp *D, uint32_t crc, const part_crc *all)
{
    for (int k = 0; k < PFSPH__CKPT_ARRAYS; k++) {
        const void *p;
        const size_t es = pfsph__checkpoint_array(D->sim->ctx.fluid, k, 0, &p);
        for (int q = 0; q < D->size; q++)
            if (all[q].m) crc = (uint32_t)crc32_combine(crc, all[q].crc[k], (z_off_t)(all[q].m * es));
    }
    return crc;
}

int pfsph_decomp_save(pfsph_decomp *D, const char *path, int frame, int durable, size_t *bytes, pfsph_error *err)
{
    const pfsph_sim *sim = D->sim;
    int hd[2] = {frame, durable};
    MPI_Bcast(hd, 2, MPI_INT, 0, D->comm);
    frame = hd[0], durable = hd[1];
    char *dest = share_str(D, path), tmp[PFSPH_PATH_LEN + 96] = "";
    int rc = PFSPH_OK;
    /* the root makes the temporary file, as the serial writer does (the final name is touched
     * only by the rename); every rank must see it: a run directory every rank shares */
    if (D->rank == 0) {
        snprintf(tmp, sizeof tmp, "%s.tmp.%ld", dest, (long)getpid());
        int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd < 0) rc = pfsph_fail(err, PFSPH_EIO, "%s: cannot create temporary file: %s", dest, strerror(errno));
        else close(fd);
        if (!rc && pfsph__write_fault(dest))
            rc = pfsph_fail(err, PFSPH_EIO, "%s: write failed: %s", dest, strerror(ENOSPC));
    }
    MPI_Bcast(tmp, sizeof tmp, MPI_CHAR, 0, D->comm);
    if (!rc && D->rank && access(tmp, W_OK) != 0) {
        char host[MPI_MAX_PROCESSOR_NAME] = "?";
        int len;
        MPI_Get_processor_name(host, &len);
        rc = pfsph_fail(err, PFSPH_EIO,
                        "%s: rank %d (on %s) cannot see the checkpoint's temporary file (%s): every rank writes its "
                        "part of a checkpoint, so the run directory must be on a filesystem all ranks share, at the "
                        "same path (docs/cluster.md)",
                        tmp, D->rank, host, strerror(errno));
    }
    MPI_File fh = MPI_FILE_NULL;
    if (!(rc = pfsph_decomp_first_failure(D, rc, err)) &&
        MPI_File_open(D->comm, tmp, MPI_MODE_WRONLY, MPI_INFO_NULL, &fh) != MPI_SUCCESS)
        rc = pfsph_fail(err, PFSPH_EIO, "%s: MPI_File_open failed on rank %d", tmp, D->rank);
    if ((rc = pfsph_decomp_first_failure(D, rc, err))) {
        if (fh != MPI_FILE_NULL) MPI_File_close(&fh);
        if (D->rank == 0 && *tmp) unlink(tmp);
        free(dest);
        return D->d.agree(&D->d, rc, err);
    }
    size_t l0, m;
    uint64_t g0, N, mmax, sz[2] = {0, 0}; /* head, payload */
    my_part(D, &l0, &g0, &m);
    uint64_t mm = m;
    MPI_Allreduce(&mm, &N, 1, MPI_UINT64_T, MPI_SUM, D->comm);
    MPI_Allreduce(&mm, &mmax, 1, MPI_UINT64_T, MPI_MAX, D->comm);
    if (D->rank == 0) { /* the root's diffuse set, bodies and emitters: the sizes are its */
        size_t h, pl;
        pfsph__checkpoint_sizes(sim, N, &h, &pl);
        sz[0] = h, sz[1] = pl;
    }
    MPI_Bcast(sz, 2, MPI_UINT64_T, 0, D->comm);
    int bad = 0, e = 0;
    isink s = {fh, PFSPH__CKPT_HEADER};
    uint32_t crc = (uint32_t)crc32(0L, Z_NULL, 0);
    if (D->rank == 0) e = pfsph__checkpoint_head(sim, frame, N, file_sink, &s, &crc);
    /* the fluid's arrays, each rank its part at its place */
    unsigned char *stage = pfsph__host_le() ? NULL : malloc(STAGE);
    if (!pfsph__host_le() && !stage) MPI_Abort(D->comm, 1);
    part_crc mine = {m, {0}}, *all = NULL;
    MPI_Offset off = (MPI_Offset)(PFSPH__CKPT_HEADER + sz[0]);
    for (int k = 0; k < PFSPH__CKPT_ARRAYS; k++) {
        const void *p;
        const size_t es = pfsph__checkpoint_array(D->sim->ctx.fluid, k, 0, &p);
        bad |= write_array(D, fh, off + (MPI_Offset)(g0 * es), k, l0, m, (size_t)mmax, stage, &mine.crc[k]);
        off += (MPI_Offset)(N * es);
    }
    free(stage);
    if (D->rank == 0 && !(all = malloc((size_t)D->size * sizeof *all))) MPI_Abort(D->comm, 1);
    MPI_Gather(&mine, sizeof mine, MPI_BYTE, all, sizeof mine, MPI_BYTE, 0, D->comm);
    if (D->rank == 0) { /* the tail after the arrays, the CRC on over it, then the header */
        crc = combine(D, crc, all);
        size_t tl = 0;
        s.off = off;
        if (!e) e = pfsph__checkpoint_tail(sim, file_sink, &s, &crc, &tl);
        if (!e && (uint64_t)off + tl != PFSPH__CKPT_HEADER + sz[1])
            rc = pfsph_fail(err, PFSPH_EIO, "%s: internal size mismatch (%llu != %llu)", dest,
                            (unsigned long long)((uint64_t)off + tl), (unsigned long long)(PFSPH__CKPT_HEADER + sz[1]));
        unsigned char head[PFSPH__CKPT_HEADER];
        pfsph__checkpoint_header(head, sim, sz[1], crc);
        s.off = 0;
        if (!e && !rc) e = file_sink(&s, head, sizeof head);
        free(all);
    }
    if (durable && MPI_File_sync(fh) != MPI_SUCCESS) bad = 1;
    if (MPI_File_close(&fh) != MPI_SUCCESS) bad = 1;
    if (!rc && (e || bad))
        rc = pfsph_fail(err, PFSPH_EIO, "%s: write failed on rank %d: %s", dest, D->rank, strerror(e ? e : EIO));
    rc = pfsph_decomp_first_failure(D, rc, err);
    if (D->rank == 0 && !rc) { /* into place, as the serial writer does */
        if (durable) rc = pfsph__rename_durable(tmp, dest, err);
        else if (rename(tmp, dest) != 0)
            rc = pfsph_fail(err, PFSPH_EIO, "%s: rename failed: %s", dest, strerror(errno));
    }
    if (D->rank == 0 && rc) unlink(tmp);
    free(dest);
    D->ckpt_bytes =
        m * PFSPH__CKPT_PER_PARTICLE + (D->rank == 0 ? PFSPH__CKPT_HEADER + sz[1] - N * PFSPH__CKPT_PER_PARTICLE : 0);
    if (bytes) *bytes = (size_t)(PFSPH__CKPT_HEADER + sz[1]);
    return D->d.agree(&D->d, rc, err);
}

/* Array k of the range [a, a + cnt) from the file at off (the set's array k begins there) into
 * ps, every rank in the same number of collective calls; the CRC32 of the file's bytes. */
static int read_array(MPI_File fh, MPI_Offset off, pfsph_particles *ps, int k, uint64_t a, size_t cnt, size_t cmax,
                      uint32_t *crc)
{
    const void *p;
    const size_t es = pfsph__checkpoint_array(ps, k, 0, &p);
    const size_t bytes = cnt * es, rounds = (cmax * es + CHUNK - 1) / CHUNK;
    unsigned char *dst = (unsigned char *)p;
    int bad = 0;
    *crc = (uint32_t)crc32(0L, Z_NULL, 0);
    for (size_t r = 0; r < (rounds ? rounds : 1); r++) {
        const size_t lo = r * CHUNK < bytes ? r * CHUNK : bytes, hi = lo + CHUNK < bytes ? lo + CHUNK : bytes;
        if (MPI_File_read_at_all(fh, off + (MPI_Offset)(a * es + lo), dst + lo, (int)(hi - lo), MPI_BYTE,
                                 MPI_STATUS_IGNORE) != MPI_SUCCESS)
            bad = 1;
        *crc = crc_of(*crc, dst + lo, hi - lo);
    }
    if (!pfsph__host_le() && es > 1) /* the file is little-endian */
        for (size_t i = 0; i < cnt; i++) {
            unsigned char v[8];
            memcpy(v, dst + i * es, es);
            pfsph__get_le(dst + i * es, v, es);
        }
    return bad;
}

/* The root's bytes of the file besides the fluid's arrays: at most n from off into b. */
static int read_root(MPI_File fh, MPI_Offset off, unsigned char *b, size_t n)
{
    MPI_Status st;
    int got = 0;
    for (size_t o = 0; o < n;) {
        const size_t k = n - o > CHUNK ? CHUNK : n - o;
        if (MPI_File_read_at(fh, off + (MPI_Offset)o, b + o, (int)k, MPI_BYTE, &st) != MPI_SUCCESS) return -1;
        MPI_Get_count(&st, MPI_BYTE, &got);
        if ((size_t)got != k) return -1;
        o += k;
    }
    return 0;
}

int pfsph_decomp_load(pfsph_decomp *D, const char *path, long expect_frame, struct pfsph_checkpoint_info *info,
                      pfsph_error *err)
{
    pfsph_sim *sim = D->sim;
    long long ef = expect_frame;
    MPI_Bcast(&ef, 1, MPI_LONG_LONG, 0, D->comm);
    char *name = share_str(D, path);
    MPI_File fh = MPI_FILE_NULL;
    MPI_Offset fsize = 0;
    int rc = PFSPH_OK;
    if (MPI_File_open(D->comm, name, MPI_MODE_RDONLY, MPI_INFO_NULL, &fh) != MPI_SUCCESS)
        rc = pfsph_fail(err, PFSPH_EIO,
                        "%s: cannot open on rank %d (every rank reads its part: the run directory "
                        "must be on a filesystem all ranks share)",
                        name, D->rank);
    else MPI_File_get_size(fh, &fsize);
    if ((rc = pfsph_decomp_first_failure(D, rc, err))) {
        if (fh != MPI_FILE_NULL) MPI_File_close(&fh);
        free(name);
        return rc;
    }
    /* the root: the header and the head, up to the fluid's count and next id */
    size_t h, pl;
    pfsph__checkpoint_sizes(sim, 0, &h, &pl);
    const uint64_t per = PFSPH__CKPT_PER_PARTICLE, flen = (uint64_t)fsize;
    uint64_t hd[3] = {0, 0, 0}; /* ok, n, next id */
    unsigned char *buf = NULL;
    if (D->rank == 0) {
        const size_t first = flen < PFSPH__CKPT_HEADER + h ? (size_t)flen : PFSPH__CKPT_HEADER + h;
        if (!(buf = malloc(PFSPH__CKPT_HEADER + h))) MPI_Abort(D->comm, 1);
        int got = read_root(fh, 0, buf, first) == 0;
        if (got && first == PFSPH__CKPT_HEADER + h && !memcmp(buf, PFSPH__CKPT_MAGIC, 8)) {
            uint64_t n;
            uint32_t nid;
            pfsph__get_le(&n, buf + PFSPH__CKPT_HEADER + h - 12, 8);
            pfsph__get_le(&nid, buf + PFSPH__CKPT_HEADER + h - 4, 4);
            if (n <= (flen - PFSPH__CKPT_HEADER - h) / per) hd[0] = 1, hd[1] = n, hd[2] = nid;
        }
        if (!got) rc = pfsph_fail(err, PFSPH_EIO, "%s: read failed", name);
        else if (!hd[0]) { /* the serial reader says what is wrong with what there is */
            pfsph__ckpt_elided el = {flen, 0, NULL};
            rc = pfsph__checkpoint_read_elided(sim, buf, first, name, expect_frame, &el, NULL, err);
            if (!rc) rc = pfsph_fail(err, PFSPH_EINPUT, "%s: corrupt checkpoint", name);
        }
    }
    MPI_Bcast(hd, 3, MPI_UINT64_T, 0, D->comm);
    if ((rc = pfsph_decomp_first_failure(D, rc, err))) {
        MPI_File_close(&fh);
        free(buf);
        free(name);
        return rc;
    }
    /* every rank its range [a, a + cnt) of the serial order, about 1/ranks of it */
    const uint64_t n = hd[1], a = n * (uint64_t)D->rank / (uint64_t)D->size,
                   b = n * (uint64_t)(D->rank + 1) / (uint64_t)D->size, cmax = (n + (uint64_t)D->size - 1) / D->size;
    const size_t cnt = (size_t)(b - a);
    pfsph_particles part;
    memset(&part, 0, sizeof part);
    if (pfsph_particles_init(&part, cnt ? cnt : 1)) MPI_Abort(D->comm, 1); /* every rank waits in the reads */
    part.n = cnt;
    part.next_id = (uint32_t)hd[2];
    part_crc mine = {cnt, {0}}, *all = NULL;
    MPI_Offset off = (MPI_Offset)(PFSPH__CKPT_HEADER + h);
    int bad = 0;
    for (int k = 0; k < PFSPH__CKPT_ARRAYS; k++) {
        const void *p;
        const size_t es = pfsph__checkpoint_array(&part, k, 0, &p);
        bad |= read_array(fh, off, &part, k, a, cnt, (size_t)cmax, &mine.crc[k]);
        off += (MPI_Offset)(n * es);
    }
    if (bad) rc = pfsph_fail(err, PFSPH_EIO, "%s: read failed on rank %d", name, D->rank);
    else rc = pfsph__checkpoint_check_set(&part, (size_t)a, name, "fluid", err);
    if (D->rank == 0 && !(all = malloc((size_t)D->size * sizeof *all))) MPI_Abort(D->comm, 1);
    MPI_Gather(&mine, sizeof mine, MPI_BYTE, all, sizeof mine, MPI_BYTE, 0, D->comm);
    if (!(rc = pfsph_decomp_first_failure(D, rc, err)) && D->rank == 0) {
        /* the tail, after the header and the head; the CRC over the head, the parts, the tail */
        const size_t tl = (size_t)(flen - (uint64_t)off);
        unsigned char *q = realloc(buf, PFSPH__CKPT_HEADER + h + tl);
        if (!q) MPI_Abort(D->comm, 1);
        buf = q;
        if (read_root(fh, off, buf + PFSPH__CKPT_HEADER + h, tl))
            rc = pfsph_fail(err, PFSPH_EIO, "%s: read failed", name);
        uint32_t crc = crc_of((uint32_t)crc32(0L, Z_NULL, 0), buf + PFSPH__CKPT_HEADER, h);
        crc = combine(D, crc, all);
        crc = crc_of(crc, buf + PFSPH__CKPT_HEADER + h, tl);
        pfsph__ckpt_elided el = {flen, crc, &part};
        if (!rc)
            rc = pfsph__checkpoint_read_elided(sim, buf, PFSPH__CKPT_HEADER + h + tl, name, expect_frame, &el, info,
                                               err);
    }
    free(all);
    free(buf);
    MPI_File_close(&fh);
    if (!(rc = pfsph_decomp_first_failure(D, rc, err))) {
        /* the root restored its range and the rest: the others their ranges, with its clock */
        pfsph_sim_state st;
        pfsph_sim_get_state(sim, &st);
        MPI_Bcast(&st, sizeof st, MPI_BYTE, 0, D->comm);
        pfsph_particles none;
        memset(&none, 0, sizeof none);
        if (D->rank) rc = pfsph_sim_restore(sim, &st, &part, sim->st.df ? &none : NULL, 0, 0, err);
        rc = pfsph_decomp_first_failure(D, rc, err);
    }
    if (!rc) { /* the next exchange sends each particle to its owners and shares the root's state */
        D->root_all = 0;
        D->gathered = 0;
        D->share = 1;
        D->d.own_lo = 0;
        D->d.own_hi = cnt;
        D->own_g0 = a;
        D->d.nglobal = (size_t)n;
        D->ckpt_read = cnt * per + (D->rank == 0 ? flen - n * per : 0);
    }
    pfsph_particles_free(&part);
    free(name);
    return rc;
}

static int load_hook(pfsph_dist *d, const char *path, long expect_frame, struct pfsph_checkpoint_info *info,
                     pfsph_error *err)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    pfsph_mpi_cmd c = {PFSPH_MPI_LOAD, 0, 0};
    pfsph_decomp_cmd(D, &c); /* the root: the others follow */
    return pfsph_decomp_load(D, path, expect_frame, info, err);
}

static int save_hook(pfsph_dist *d, const char *path, int frame, int durable, size_t *bytes, pfsph_error *err)
{
    pfsph_decomp *D = (pfsph_decomp *)d;
    pfsph_mpi_cmd c = {PFSPH_MPI_SAVE, 0, 0};
    pfsph_decomp_cmd(D, &c); /* the root: the others follow */
    return pfsph_decomp_save(D, path, frame, durable, bytes, err);
}

void pfsph_decomp_ckpt_hooks(pfsph_decomp *D)
{
    /* PFSPH_MPI_CHECKPOINTS=root: the root writes and reads them alone, after the frame's gather
     * and before a scatter, as before (a run directory only the root's machine sees) */
    const char *v = getenv("PFSPH_MPI_CHECKPOINTS");
    if (v && !strcmp(v, "root")) return;
    D->d.save = save_hook;
    D->d.load = load_hook;
}
