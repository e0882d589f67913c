/* `pfsph view`: the live viewer (a scene simulated in a window) and replay of a run directory.
 * Built only when GLFW and libepoxy are found (CMake option PFSPH_VIEWER); docs/viewer.md. */
#ifndef PFSPH_VIEW_H
#define PFSPH_VIEW_H

extern const char *const pfsph_view_help;

/* The command: argv are the arguments after "view". Returns the exit status (0, 1, 2, 3). */
int pfsph_view_main(int argc, char **argv);

#endif
