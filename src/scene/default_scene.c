/* The embedded default scene (`pfsph run` with no file): a small 3D dam break against a
 * cylinder, about 10k fluid particles, sized to finish in about a minute on two cores. */
#include "pfsph/scene.h"

static const char default_json[] =
    "{\n"
    "  \"name\": \"default dam break\",\n"
    "  \"comment\": \"Embedded default scene: a 0.4 x 0.5 x 0.4 m water column collapses "
    "against a vertical cylinder in an open 1.2 x 0.8 x 0.4 m tank.\",\n"
    "  \"dimension\": 3,\n"
    "  \"particle_radius\": 0.01,\n"
    "  \"support_factor\": 2.0,\n"
    "  \"gravity\": [0, -9.81, 0],\n"
    "  \"domain\": {\"min\": [-0.1, -0.1, -0.1], \"max\": [1.3, 1.3, 0.5]},\n"
    "  \"solver\": {\"type\": \"wcsph\"},\n"
    "  \"time\": {\"end\": 1.2, \"fps\": 25, \"cfl\": 0.4, \"dt_min\": 1e-6, \"dt_max\": 0.005},\n"
    "  \"seed\": 1,\n"
    "  \"threads\": 0,\n"
    "  \"phases\": [\n"
    "    {\"name\": \"water\", \"kind\": \"fluid\", \"rest_density\": 1000, \"viscosity\": 1e-3, "
    "\"color\": [0.2, 0.4, 0.9]},\n"
    "    {\"name\": \"wall\", \"kind\": \"solid\", \"color\": [0.6, 0.6, 0.62]}\n"
    "  ],\n"
    "  \"fluid\": [\n"
    "    {\"shape\": \"box\", \"min\": [0, 0, 0], \"max\": [0.4, 0.5, 0.4], \"phase\": \"water\"}\n"
    "  ],\n"
    "  \"solids\": [\n"
    "    {\"shape\": \"container\", \"min\": [0, 0, 0], \"max\": [1.2, 0.8, 0.4], "
    "\"open_top\": true, \"layers\": 2, \"phase\": \"wall\"},\n"
    "    {\"shape\": \"cylinder\", \"center\": [0.8, 0.35, 0.2], \"radius\": 0.06, "
    "\"height\": 0.7, \"axis\": \"y\", \"layers\": 2, \"phase\": \"wall\"}\n"
    "  ],\n"
    "  \"output\": {\"directory\": \"pfsph_default_run\", \"formats\": [\"vtp\", \"ply\"], "
    "\"fields\": [\"speed\"], \"boundary\": true, \"frame_interval\": 1},\n"
    "  \"camera\": {\"eye\": [1.6, 1.1, 1.7], \"target\": [0.6, 0.3, 0.2], \"up\": [0, 1, 0], "
    "\"fov\": 40, \"width\": 960, \"height\": 540, \"color_by\": \"phase\"}\n"
    "}\n";

const char *pfsph_scene_default_json(void) { return default_json; }
