/* The liquid's velocity at the vertices of its surface mesh (surface_mesh.h), so that renderers
 * can blur the motion of a mesh sequence whose vertices do not correspond from frame to frame. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/surface_mesh.h"

typedef struct cellpt {
    int64_t key;
    uint32_t i;
} cellpt;

static int cmp(const void *a, const void *b)
{
    const cellpt *p = a, *q = b;
    if (p->key != q->key) return p->key < q->key ? -1 : 1;
    return p->i < q->i ? -1 : (p->i > q->i);
}

static int64_t key3(int64_t a, int64_t b, int64_t c)
{
    const int64_t B = (int64_t)1 << 20;
    return ((a + B) << 42) | ((b + B) << 21) | (c + B);
}

/* the first entry with key >= k */
static size_t lower(const cellpt *c, size_t n, int64_t k)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (c[mid].key < k) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

int pfsph_surface_velocity(pfsph_surface_mesh *m, const double *x, const float *v, size_t n, double R)
{
    free(m->vel);
    m->vel = calloc(3 * (m->nverts ? m->nverts : 1), sizeof *m->vel);
    cellpt *c = malloc((n ? n : 1) * sizeof *c);
    if (!m->vel || !c) {
        free(c);
        return PFSPH_ENOMEM;
    }
    const double inv = 1.0 / R, R2 = R * R;
    const double lim = (double)((1 << 20) - 2); /* cells beyond the key's range are clamped */
    for (size_t i = 0; i < n; i++) {
        int64_t k[3];
        for (int a = 0; a < 3; a++) {
            double q = floor(x[3 * i + a] * inv);
            k[a] = (int64_t)(q < -lim ? -lim : q > lim ? lim : q);
        }
        c[i].key = key3(k[0], k[1], k[2]);
        c[i].i = (uint32_t)i;
    }
    qsort(c, n, sizeof *c, cmp);
#pragma omp parallel for schedule(static)
    for (size_t j = 0; j < m->nverts; j++) {
        const double *p = m->v + 3 * j;
        int64_t k[3];
        for (int a = 0; a < 3; a++) {
            double q = floor(p[a] * inv);
            k[a] = (int64_t)(q < -lim ? -lim : q > lim ? lim : q);
        }
        double sw = 0, sv[3] = {0, 0, 0};
        for (int64_t a = k[0] - 1; a <= k[0] + 1; a++)
            for (int64_t b = k[1] - 1; b <= k[1] + 1; b++)
                for (int64_t cc = k[2] - 1; cc <= k[2] + 1; cc++) {
                    const int64_t key = key3(a, b, cc);
                    for (size_t e = lower(c, n, key); e < n && c[e].key == key; e++) {
                        const size_t i = c[e].i;
                        double r2 = 0;
                        for (int u = 0; u < 3; u++) r2 += (x[3 * i + u] - p[u]) * (x[3 * i + u] - p[u]);
                        if (r2 >= R2) continue;
                        double t = 1 - r2 / R2, w = t * t * t;
                        sw += w;
                        for (int u = 0; u < 3; u++) sv[u] += w * v[3 * i + u];
                    }
                }
        if (sw > 0)
            for (int u = 0; u < 3; u++) m->vel[3 * j + u] = (float)(sv[u] / sw);
    }
    free(c);
    return PFSPH_OK;
}
