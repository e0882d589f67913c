/* The figure of docs/viscosity.md: the measured bulk viscosity against the Morris viscosity
 * applied, from a CSV of "series,nu_morris,nu_eff" rows (docs/data/viscosity_bulk.csv), one line
 * per series, drawn with the project's own line charts (pfsph_plot_lines).
 *
 *   pf_visc_plot in.csv out.png */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pfsph/io.h"

#define MAXS 8
#define MAXP 64

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: pf_visc_plot in.csv out.png\n");
        return 2;
    }
    FILE *fp = fopen(argv[1], "r");
    if (!fp) {
        perror(argv[1]);
        return 2;
    }
    static char names[MAXS][64];
    static double x[MAXS][MAXP], y[MAXS][MAXP];
    size_t n[MAXS] = {0};
    int ns = 0;
    char line[256];
    if (!fgets(line, sizeof line, fp)) return 2; /* header */
    while (fgets(line, sizeof line, fp)) {
        char *c1 = strchr(line, ','), *c2 = c1 ? strchr(c1 + 1, ',') : NULL;
        if (!c2) continue;
        *c1 = 0;
        int k = 0;
        while (k < ns && strcmp(names[k], line) != 0) k++;
        if (k == ns) {
            if (ns == MAXS) continue;
            snprintf(names[ns++], sizeof names[0], "%s", line);
        }
        if (n[k] < MAXP) {
            x[k][n[k]] = 1e3 * atof(c1 + 1); /* in mm^2/s */
            y[k][n[k]] = 1e3 * atof(c2 + 1);
            n[k]++;
        }
    }
    fclose(fp);
    pfsph_plot_series s[MAXS];
    for (int k = 0; k < ns; k++) s[k] = (pfsph_plot_series){names[k], x[k], y[k], n[k], 0};
    pfsph_error err = {0};
    if (pfsph_plot_lines(argv[2], "Bulk viscosity of the hot pair-force liquid",
                         "Morris viscosity applied [1e-3 m^2/s]", "effective viscosity [1e-3 m^2/s]", s, ns,
                         &err) != PFSPH_OK) {
        fprintf(stderr, "%s\n", err.msg);
        return 1;
    }
    return 0;
}
