/* OpenGL drawing for the viewer (draw.h). Shading, colours, background and the two-layer
 * composite follow the PNG renderer (src/io/render_raster.c, render.c) so that both show the
 * same picture. */
#include "view/draw.h"

#include <epoxy/gl.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/colormap.h"
#include "io/font.h"

typedef struct layer {
    GLuint fbo, col, depth;
} layer;

struct pfsph_vmesh {
    GLuint vao, vbo, ebo;
    size_t nv, ni; /* vertices; indices (0: unindexed) */
};

struct pfsph_vdraw {
    GLuint sprite_prog, over_prog, mesh_prog;
    GLuint comp_prog[2][2]; /* [samples per axis - 1][walls' layer used] */
    bool used[2];           /* the layers drawn into since begin */
    /* the walls' layer as last drawn: its sprites and the camera they were drawn with; a frame
     * with the same ones re-uses the layer instead of drawing them again (walls rarely move, and
     * on llvmpipe their sprites cost more than the fluid's: docs/viewer.md) */
    pfsph_vsprite *wall_spr;
    size_t wall_n, wall_cap;
    float wall_key[35];
    bool wall_valid;
    GLuint quad_vbo, inst_vbo, sprite_vao, empty_vao, over_vbo, over_vao;
    layer L[2];
    GLuint final_fbo, final_col;
    int w, h; /* size of the frame */
    int ss;   /* supersampling: the layers are ss w x ss h */
    int want_ss;
    float view[16], proj[16];
    int ortho, walls3d;
    double f;
    float *ov; /* overlay vertices: x, y, r, g, b, a */
    size_t nov, ovcap;
};

static const char *SPRITE_VS =
    "#version 330 core\n"
    "layout(location = 0) in vec2 corner;\n"
    "layout(location = 1) in vec4 posr;\n"
    "layout(location = 2) in vec4 col;\n"
    "uniform mat4 view, proj;\n"
    "uniform int ortho;\n"
    "uniform float fpx, ss;\n"
    "out vec2 uv;\n"
    "flat out vec3 vcol, vc;\n"
    "flat out float vr, relief;\n"
    "void main() {\n"
    "  vec4 c = view * vec4(posr.xyz, 1.0);\n"
    "  float r = posr.w;\n"
    "  float rp = ortho == 1 ? r * fpx : r * fpx / max(-c.z, 1e-6);\n"
    /* discs of a pixel or two are drawn flat (the renderer's relief); none smaller than 0.6 samples */
    "  relief = clamp((rp - 1.5) / 2.5, 0.0, 1.0);\n"
    "  float grow = rp * ss < 0.6 ? 0.6 / max(rp * ss, 1e-6) : 1.0;\n"
    "  uv = corner; vcol = col.rgb; vc = c.xyz; vr = r;\n"
    "  gl_Position = proj * vec4(c.xy + corner * r * grow, c.z, 1.0);\n"
    "}\n";

/* The sprites' fragment shader runs for every covered sample of every sphere (it writes depth,
 * so nothing is rejected early): on llvmpipe its length is the drawing's cost. The highlight's
 * power 28 is taken by squaring (x^16 x^8 x^4) rather than pow (exp2 and log2), and the depth
 * from the two rows of proj that give clip z and w (pfsph_vcam_matrices: x and y do not enter
 * them), the same values to rounding. */
static const char *SPRITE_FS =
    "#version 330 core\n"
    "in vec2 uv;\n"
    "flat in vec3 vcol, vc;\n"
    "flat in float vr, relief;\n"
    "uniform vec4 pzw;\n" /* clip z = pzw.x z + pzw.y, clip w = pzw.z z + pzw.w */
    "uniform int flatshade;\n"
    "out vec4 o;\n"
    "void main() {\n"
    "  float d2 = dot(uv, uv);\n"
    "  if (d2 > 1.0) discard;\n"
    "  float nz = sqrt(1.0 - d2);\n"
    "  vec3 n = vec3(uv, nz);\n"
    /* Lambert + ambient + a small highlight from the upper left, as the renderer's shade() */
    "  const vec3 L = vec3(-0.45, 0.62, 0.64), H = vec3(-0.2116, 0.2915, 0.9328);\n"
    "  float diff = max(dot(n, L), 0.0), h = max(dot(n, H), 0.0);\n"
    "  float h2 = h * h, h4 = h2 * h2, h8 = h4 * h4, spec = h8 * h8 * h8 * h4;\n"
    "  float sh = 0.32 + 0.68 * diff;\n"
    "  if (flatshade == 1) { sh = 0.75 + 0.25 * diff; spec = 0.0; }\n"
    "  sh = relief * sh + (1.0 - relief) * 0.85;\n"
    "  o = vec4(clamp(vcol * sh + 0.22 * spec * relief, 0.0, 1.0), 1.0);\n"
    "  float z = vc.z + nz * vr;\n"
    "  gl_FragDepth = clamp((pzw.x * z + pzw.y) / (pzw.z * z + pzw.w) * 0.5 + 0.5, 0.0, 1.0);\n"
    "}\n";

/* Meshes: the liquid shaded as render_raster.c's pfsph__shade_water, bodies as its
 * pfsph__shade_solid, both on the normal in camera coordinates (x right, y up, z towards the
 * viewer) as the renderer has it. */
static const char *MESH_VS = "#version 330 core\n"
                             "layout(location = 0) in vec3 pos;\n"
                             "layout(location = 1) in vec3 nrm;\n"
                             "layout(location = 2) in vec3 col;\n"
                             "uniform mat4 view, proj;\n"
                             "out vec3 vn;\n"
                             "out vec3 vcol;\n"
                             "void main() {\n"
                             "  vn = mat3(view) * nrm; vcol = col;\n"
                             "  gl_Position = proj * (view * vec4(pos, 1.0));\n"
                             "}\n";

static const char *MESH_FS =
    "#version 330 core\n"
    "in vec3 vn;\n"
    "in vec3 vcol;\n"
    "uniform int water;\n"
    "out vec4 o;\n"
    "void main() {\n"
    "  const vec3 L = vec3(-0.45, 0.62, 0.64), H = vec3(-0.2116, 0.2915, 0.9328);\n"
    "  float len = length(vn);\n"
    "  vec3 n = len > 0.0 ? vn / len : vec3(0.0, 0.0, 1.0);\n"
    "  if (water == 1) {\n"
    "    const vec3 base = vec3(0.13, 0.38, 0.72), sky = vec3(0.86, 0.91, 0.96);\n"
    "    n.z = abs(n.z);\n"
    "    float diff = max(dot(n, L), 0.0), spec = pow(max(dot(n, H), 0.0), 60.0);\n"
    "    float fr = 0.04 + 0.96 * pow(1.0 - n.z, 5.0);\n"
    "    o = vec4(clamp(base * (0.35 + 0.65 * diff) * (1.0 - fr) + sky * fr + 0.7 * spec, 0.0, 1.0), 1.0);\n"
    "  } else {\n"
    "    if (n.z < 0.0) n = -n;\n"
    "    float diff = max(dot(n, L), 0.0), spec = pow(max(dot(n, H), 0.0), 28.0);\n"
    "    o = vec4(clamp(vcol * (0.32 + 0.68 * diff) + 0.22 * spec, 0.0, 1.0), 1.0);\n"
    "  }\n"
    "}\n";

static const char *COMP_VS = "#version 330 core\n"
                             "void main() {\n"
                             "  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);\n"
                             "  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);\n"
                             "}\n";

/* The composite, compiled for each case (SS samples per pixel along each axis; WALLS: the
 * walls' layer has something in it). One general shader with a loop bound and the walls' fetches
 * taken at run time cost llvmpipe about 8 ms of CPU a 640x360 frame, more than the fluid's
 * sprites (docs/viewer.md, "What a frame costs"): constant bounds unroll, and a frame without
 * walls reads one texture instead of four. */
static const char *COMP_FS = "uniform sampler2D c0, z0, c1, z1;\n"
                             "uniform float afront, aback;\n"
                             "uniform int height;\n"
                             "out vec4 o;\n"
                             "void main() {\n"
                             "  vec3 acc = vec3(0.0);\n"
                             /* each output pixel averages SS x SS samples, each composited as the renderer does */
                             "  for (int sy = 0; sy < SS; sy++)\n"
                             "    for (int sx = 0; sx < SS; sx++) {\n"
                             "      ivec2 p = ivec2(gl_FragCoord.xy) * SS + ivec2(sx, sy);\n"
                             "      vec4 f = texelFetch(c0, p, 0);\n"
                             "      float t = height > 1 ? float(height - 1 - p.y) / float(height - 1) : 0.0;\n"
                             "      vec3 bg = mix(vec3(0.945, 0.950, 0.965), vec3(0.840, 0.850, 0.875), t);\n"
                             "      vec3 c = f.a > 0.5 ? f.rgb : bg;\n"
                             "#if WALLS\n"
                             "      vec4 b = texelFetch(c1, p, 0);\n"
                             "      if (b.a > 0.5) {\n"
                             "        float zf = texelFetch(z0, p, 0).r, zb = texelFetch(z1, p, 0).r;\n"
                             "        float a = f.a < 0.5 ? aback : (zb < zf ? afront : 0.0);\n"
                             "        c = mix(c, b.rgb, a);\n"
                             "      }\n"
                             "#endif\n"
                             "      acc += c;\n"
                             "    }\n"
                             "  o = vec4(acc / float(SS * SS), 1.0);\n"
                             "}\n";

static const char *OVER_VS = "#version 330 core\n"
                             "layout(location = 0) in vec2 p;\n"
                             "layout(location = 1) in vec4 col;\n"
                             "uniform vec2 size;\n"
                             "out vec4 vcol;\n"
                             "void main() {\n"
                             "  vcol = col;\n"
                             "  gl_Position = vec4(2.0 * p.x / size.x - 1.0, 1.0 - 2.0 * p.y / size.y, 0.0, 1.0);\n"
                             "}\n";

static const char *OVER_FS = "#version 330 core\n"
                             "in vec4 vcol;\n"
                             "out vec4 o;\n"
                             "void main() { o = vcol; }\n";

static GLuint compile(GLenum type, const char *src, char *msg, size_t cap)
{
    GLuint s = glCreateShader(type);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[1024] = "";
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        snprintf(msg, cap, "shader compilation failed: %s", log);
        glDeleteShader(s);
        return 0;
    }
    return s;
}

static GLuint program(const char *vs, const char *fs, char *msg, size_t cap)
{
    GLuint v = compile(GL_VERTEX_SHADER, vs, msg, cap);
    if (!v) return 0;
    GLuint f = compile(GL_FRAGMENT_SHADER, fs, msg, cap);
    if (!f) {
        glDeleteShader(v);
        return 0;
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, v);
    glAttachShader(p, f);
    glLinkProgram(p);
    glDeleteShader(v);
    glDeleteShader(f);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[1024] = "";
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        snprintf(msg, cap, "shader link failed: %s", log);
        glDeleteProgram(p);
        return 0;
    }
    return p;
}

pfsph_vdraw *pfsph_vdraw_create(char *msg, size_t cap)
{
    pfsph_vdraw *d = calloc(1, sizeof *d);
    if (!d) {
        snprintf(msg, cap, "out of memory");
        return NULL;
    }
    d->sprite_prog = program(SPRITE_VS, SPRITE_FS, msg, cap);
    bool ok = d->sprite_prog != 0;
    for (int k = 0; k < 4 && ok; k++) {
        char src[2048];
        snprintf(src, sizeof src, "#version 330 core\n#define SS %d\n#define WALLS %d\n%s", k / 2 + 1, k % 2, COMP_FS);
        ok = (d->comp_prog[k / 2][k % 2] = program(COMP_VS, src, msg, cap)) != 0;
    }
    d->over_prog = ok ? program(OVER_VS, OVER_FS, msg, cap) : 0;
    d->mesh_prog = d->over_prog ? program(MESH_VS, MESH_FS, msg, cap) : 0;
    if (!d->mesh_prog) {
        pfsph_vdraw_destroy(d);
        return NULL;
    }
    static const float quad[8] = {-1, -1, 1, -1, -1, 1, 1, 1};
    glGenVertexArrays(1, &d->sprite_vao);
    glBindVertexArray(d->sprite_vao);
    glGenBuffers(1, &d->quad_vbo);
    glBindBuffer(GL_ARRAY_BUFFER, d->quad_vbo);
    glBufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), (void *)0);
    glGenBuffers(1, &d->inst_vbo);
    glBindBuffer(GL_ARRAY_BUFFER, d->inst_vbo);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, sizeof(pfsph_vsprite), (void *)0);
    glVertexAttribDivisor(1, 1);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(pfsph_vsprite), (void *)(4 * sizeof(float)));
    glVertexAttribDivisor(2, 1);
    glGenVertexArrays(1, &d->empty_vao);
    glGenVertexArrays(1, &d->over_vao);
    glBindVertexArray(d->over_vao);
    glGenBuffers(1, &d->over_vbo);
    glBindBuffer(GL_ARRAY_BUFFER, d->over_vbo);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 6 * sizeof(float), (void *)0);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, 6 * sizeof(float), (void *)(2 * sizeof(float)));
    glBindVertexArray(0);
    return d;
}

static void free_targets(pfsph_vdraw *d)
{
    for (int l = 0; l < 2; l++) {
        if (d->L[l].fbo) glDeleteFramebuffers(1, &d->L[l].fbo);
        if (d->L[l].col) glDeleteTextures(1, &d->L[l].col);
        if (d->L[l].depth) glDeleteTextures(1, &d->L[l].depth);
        memset(&d->L[l], 0, sizeof d->L[l]);
    }
    if (d->final_fbo) glDeleteFramebuffers(1, &d->final_fbo);
    if (d->final_col) glDeleteTextures(1, &d->final_col);
    d->final_fbo = d->final_col = 0;
    d->w = d->h = 0;
    d->wall_valid = false;
}

void pfsph_vdraw_destroy(pfsph_vdraw *d)
{
    if (!d) return;
    free_targets(d);
    GLuint bufs[3] = {d->quad_vbo, d->inst_vbo, d->over_vbo};
    glDeleteBuffers(3, bufs);
    GLuint vaos[3] = {d->sprite_vao, d->empty_vao, d->over_vao};
    glDeleteVertexArrays(3, vaos);
    if (d->sprite_prog) glDeleteProgram(d->sprite_prog);
    for (int k = 0; k < 4; k++)
        if (d->comp_prog[k / 2][k % 2]) glDeleteProgram(d->comp_prog[k / 2][k % 2]);
    if (d->over_prog) glDeleteProgram(d->over_prog);
    if (d->mesh_prog) glDeleteProgram(d->mesh_prog);
    free(d->ov);
    free(d->wall_spr);
    free(d);
}

static GLuint texture(GLint ifmt, GLenum fmt, GLenum type, int w, int h)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexImage2D(GL_TEXTURE_2D, 0, ifmt, w, h, 0, fmt, type, NULL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return t;
}

static void make_targets(pfsph_vdraw *d, int w, int h)
{
    free_targets(d);
    /* 2 x 2 samples per pixel as the renderer takes (up to 4K frames), unless asked for 1 */
    d->ss = d->want_ss == 1 || (double)w * h > 4096.0 * 2160.0 ? 1 : 2;
    for (int l = 0; l < 2; l++) {
        d->L[l].col = texture(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, d->ss * w, d->ss * h);
        d->L[l].depth = texture(GL_DEPTH_COMPONENT24, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, d->ss * w, d->ss * h);
        glGenFramebuffers(1, &d->L[l].fbo);
        glBindFramebuffer(GL_FRAMEBUFFER, d->L[l].fbo);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, d->L[l].col, 0);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, d->L[l].depth, 0);
    }
    d->final_col = texture(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, w, h);
    glGenFramebuffers(1, &d->final_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, d->final_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, d->final_col, 0);
    d->w = w;
    d->h = h;
}

void pfsph_vdraw_set_samples(pfsph_vdraw *d, int ss)
{
    d->want_ss = ss == 1 ? 1 : 2;
    d->w = d->h = 0; /* targets are made again at the next begin */
}

int pfsph_vdraw_software(void)
{
    const char *r = (const char *)glGetString(GL_RENDERER);
    return r && (strstr(r, "llvmpipe") || strstr(r, "softpipe") || strstr(r, "swrast") || strstr(r, "Software"));
}

void pfsph_vdraw_begin(pfsph_vdraw *d, int w, int h, const float view[16], const float proj[16], int ortho, double f,
                       int walls3d)
{
    if (w != d->w || h != d->h) make_targets(d, w, h);
    memcpy(d->view, view, sizeof d->view);
    memcpy(d->proj, proj, sizeof d->proj);
    d->ortho = ortho;
    d->f = f;
    d->walls3d = walls3d;
    d->nov = 0;
    d->used[0] = d->used[1] = false;
    glViewport(0, 0, d->ss * w, d->ss * h);
    glClearColor(0, 0, 0, 0);
    glClearDepth(1.0);
    glDepthMask(GL_TRUE);
    /* the walls' layer is kept while it holds walls that may be re-used (pfsph_vdraw_sprites
     * clears it before it draws them), else cleared as the fluid's */
    for (int l = 0; l < 2; l++) {
        if (l == 1 && d->wall_valid) continue;
        glBindFramebuffer(GL_FRAMEBUFFER, d->L[l].fbo);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    }
    /* the clears go to llvmpipe's rasteriser now, not in one scene with what follows: a scene
     * that starts with a clear and then bins a mesh of 50-70k triangles took 3x the CPU
     * (measured, 60 paused frames of the wetting scene's surface: 8 s without, 2.4-3 s with) */
    glFlush();
}

/* Whether the walls' layer already holds these n sprites drawn with this frame's camera; if
 * not, remember them as what it is about to hold (false also when out of memory: drawn anyway). */
static bool walls_cached(pfsph_vdraw *d, const pfsph_vsprite *s, size_t n)
{
    float key[35];
    memcpy(key, d->view, sizeof d->view);
    memcpy(key + 16, d->proj, sizeof d->proj);
    key[32] = (float)d->ortho + 2.0f * (float)d->walls3d;
    key[33] = (float)d->f;
    key[34] = (float)d->ss;
    if (d->wall_valid && n == d->wall_n && !memcmp(key, d->wall_key, sizeof key) &&
        !memcmp(s, d->wall_spr, n * sizeof *s))
        return true;
    d->wall_valid = false;
    if (n > d->wall_cap) {
        pfsph_vsprite *q = realloc(d->wall_spr, n * sizeof *q);
        if (!q) return false;
        d->wall_spr = q;
        d->wall_cap = n;
    }
    memcpy(d->wall_spr, s, n * sizeof *s);
    memcpy(d->wall_key, key, sizeof key);
    d->wall_n = n;
    d->wall_valid = true;
    return false;
}

void pfsph_vdraw_sprites(pfsph_vdraw *d, int layer, const pfsph_vsprite *s, size_t n)
{
    if (!n) return;
    d->used[layer ? 1 : 0] = true;
    if (layer && walls_cached(d, s, n)) return;
    glBindFramebuffer(GL_FRAMEBUFFER, d->L[layer ? 1 : 0].fbo);
    if (layer) glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glViewport(0, 0, d->ss * d->w, d->ss * d->h);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_BLEND);
    glUseProgram(d->sprite_prog);
    glUniformMatrix4fv(glGetUniformLocation(d->sprite_prog, "view"), 1, GL_FALSE, d->view);
    glUniformMatrix4fv(glGetUniformLocation(d->sprite_prog, "proj"), 1, GL_FALSE, d->proj);
    glUniform1i(glGetUniformLocation(d->sprite_prog, "ortho"), d->ortho);
    glUniform4f(glGetUniformLocation(d->sprite_prog, "pzw"), d->proj[10], d->proj[14], d->proj[11], d->proj[15]);
    glUniform1f(glGetUniformLocation(d->sprite_prog, "fpx"), (float)d->f);
    glUniform1f(glGetUniformLocation(d->sprite_prog, "ss"), (float)d->ss);
    glUniform1i(glGetUniformLocation(d->sprite_prog, "flatshade"), layer && d->walls3d);
    glBindVertexArray(d->sprite_vao);
    glBindBuffer(GL_ARRAY_BUFFER, d->inst_vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(n * sizeof *s), s, GL_STREAM_DRAW);
    glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)n);
    glBindVertexArray(0);
    glDisable(GL_DEPTH_TEST);
}

pfsph_vmesh *pfsph_vmesh_create(void)
{
    pfsph_vmesh *m = calloc(1, sizeof *m);
    if (!m) return NULL;
    glGenVertexArrays(1, &m->vao);
    glBindVertexArray(m->vao);
    glGenBuffers(1, &m->vbo);
    glGenBuffers(1, &m->ebo);
    glBindBuffer(GL_ARRAY_BUFFER, m->vbo);
    for (int a = 0; a < 3; a++) {
        glEnableVertexAttribArray((GLuint)a);
        glVertexAttribPointer((GLuint)a, 3, GL_FLOAT, GL_FALSE, 9 * sizeof(float), (void *)(3 * a * sizeof(float)));
    }
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m->ebo); /* part of the VAO's state */
    glBindVertexArray(0);
    return m;
}

void pfsph_vmesh_upload(pfsph_vmesh *m, const float *vert, size_t nv, const uint32_t *idx, size_t ni)
{
    glBindVertexArray(m->vao);
    glBindBuffer(GL_ARRAY_BUFFER, m->vbo);
    /* a replayed frame is uploaded once and drawn many times (orbiting): static draw */
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * 9 * sizeof(float)), nv ? vert : NULL, GL_STATIC_DRAW);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)((idx ? ni : 0) * sizeof(uint32_t)), idx && ni ? idx : NULL,
                 GL_STATIC_DRAW);
    glBindVertexArray(0);
    m->nv = nv;
    m->ni = idx ? ni : 0;
}

void pfsph_vmesh_destroy(pfsph_vmesh *m)
{
    if (!m) return;
    glDeleteBuffers(1, &m->vbo);
    glDeleteBuffers(1, &m->ebo);
    glDeleteVertexArrays(1, &m->vao);
    free(m);
}

void pfsph_vdraw_mesh(pfsph_vdraw *d, const pfsph_vmesh *m, int water)
{
    if (!m || !m->nv) return;
    glBindFramebuffer(GL_FRAMEBUFFER, d->L[0].fbo);
    glViewport(0, 0, d->ss * d->w, d->ss * d->h);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE); /* the nearest face wins by depth, as in the renderer */
    glUseProgram(d->mesh_prog);
    glUniformMatrix4fv(glGetUniformLocation(d->mesh_prog, "view"), 1, GL_FALSE, d->view);
    glUniformMatrix4fv(glGetUniformLocation(d->mesh_prog, "proj"), 1, GL_FALSE, d->proj);
    glUniform1i(glGetUniformLocation(d->mesh_prog, "water"), water ? 1 : 0);
    glBindVertexArray(m->vao);
    if (m->ni) glDrawElements(GL_TRIANGLES, (GLsizei)m->ni, GL_UNSIGNED_INT, (void *)0);
    else glDrawArrays(GL_TRIANGLES, 0, (GLsizei)m->nv);
    glBindVertexArray(0);
    glDisable(GL_DEPTH_TEST);
}

void pfsph_vdraw_composite(pfsph_vdraw *d)
{
    glBindFramebuffer(GL_FRAMEBUFFER, d->final_fbo);
    glViewport(0, 0, d->w, d->h);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    const GLuint prog = d->comp_prog[d->ss == 2][d->used[1]];
    glUseProgram(prog);
    /* only the textures the program reads (a frame without walls: the fluid's colour) */
    GLuint tex[4] = {d->L[0].col, 0, 0, 0};
    if (d->used[1]) tex[1] = d->L[0].depth, tex[2] = d->L[1].col, tex[3] = d->L[1].depth;
    const char *names[4] = {"c0", "z0", "c1", "z1"};
    for (int k = 0; k < 4; k++) {
        glActiveTexture(GL_TEXTURE0 + k);
        glBindTexture(GL_TEXTURE_2D, tex[k]);
        glUniform1i(glGetUniformLocation(prog, names[k]), k); /* -1 (a no-op) where unused */
    }
    /* walls in front of the fluid are see-through in 3D; in 2D they sit behind it */
    glUniform1f(glGetUniformLocation(prog, "afront"), d->walls3d ? 0.28f : 1.0f);
    glUniform1f(glGetUniformLocation(prog, "aback"), d->walls3d ? 0.85f : 1.0f);
    glUniform1i(glGetUniformLocation(prog, "height"), d->ss * d->h);
    glBindVertexArray(d->empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glActiveTexture(GL_TEXTURE0);
}

static void ov_vertex(pfsph_vdraw *d, float x, float y, const float c[4])
{
    if (d->nov + 6 > d->ovcap) {
        size_t cap = d->ovcap ? 2 * d->ovcap : 6 * 4096;
        float *q = realloc(d->ov, cap * sizeof *q);
        if (!q) return;
        d->ov = q;
        d->ovcap = cap;
    }
    float *v = d->ov + d->nov;
    v[0] = x, v[1] = y, v[2] = c[0], v[3] = c[1], v[4] = c[2], v[5] = c[3];
    d->nov += 6;
}

static void quad4(pfsph_vdraw *d, float x, float y, float w, float h, const float c00[4], const float c10[4])
{
    /* c00 on the left edge, c10 on the right */
    ov_vertex(d, x, y, c00);
    ov_vertex(d, x + w, y, c10);
    ov_vertex(d, x, y + h, c00);
    ov_vertex(d, x + w, y, c10);
    ov_vertex(d, x + w, y + h, c10);
    ov_vertex(d, x, y + h, c00);
}

void pfsph_vdraw_rect(pfsph_vdraw *d, float x, float y, float w, float h, const float rgba[4])
{
    quad4(d, x, y, w, h, rgba, rgba);
}

void pfsph_vdraw_colorbar(pfsph_vdraw *d, float x, float y, float w, float h)
{
    const int seg = 32;
    for (int i = 0; i < seg; i++) {
        float a[4] = {0, 0, 0, 1}, b[4] = {0, 0, 0, 1};
        pfsph__viridis((double)i / seg, a);
        pfsph__viridis((double)(i + 1) / seg, b);
        quad4(d, x + w * i / seg, y, w / seg, h, a, b);
    }
}

float pfsph_vdraw_text(pfsph_vdraw *d, float x, float y, float sc, const char *s, const float rgba[4])
{
    for (; *s; s++) {
        const char *rows = pfsph_font_glyph(*s);
        if (rows)
            for (int r = 0; r < PFSPH_FONT_H; r++)
                for (int k = 0; k < PFSPH_FONT_W; k++)
                    if (rows[PFSPH_FONT_W * r + k] == '#') pfsph_vdraw_rect(d, x + k * sc, y + r * sc, sc, sc, rgba);
        x += PFSPH_FONT_ADVANCE * sc;
    }
    return x;
}

void pfsph_vdraw_overlay(pfsph_vdraw *d)
{
    if (!d->nov) return;
    glBindFramebuffer(GL_FRAMEBUFFER, d->final_fbo);
    glViewport(0, 0, d->w, d->h);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(d->over_prog);
    glUniform2f(glGetUniformLocation(d->over_prog, "size"), (float)d->w, (float)d->h);
    glBindVertexArray(d->over_vao);
    glBindBuffer(GL_ARRAY_BUFFER, d->over_vbo);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(d->nov * sizeof(float)), d->ov, GL_STREAM_DRAW);
    glDrawArrays(GL_TRIANGLES, 0, (GLsizei)(d->nov / 6));
    glBindVertexArray(0);
    glDisable(GL_BLEND);
    d->nov = 0;
}

void pfsph_vdraw_present(pfsph_vdraw *d, int fb_w, int fb_h)
{
    glBindFramebuffer(GL_READ_FRAMEBUFFER, d->final_fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, d->w, d->h, 0, 0, fb_w, fb_h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void pfsph_vdraw_read(pfsph_vdraw *d, uint8_t *rgb)
{
    glBindFramebuffer(GL_READ_FRAMEBUFFER, d->final_fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, d->w, d->h, GL_RGB, GL_UNSIGNED_BYTE, rgb);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    /* OpenGL's rows start at the bottom */
    size_t row = (size_t)d->w * 3;
    uint8_t *tmp = malloc(row);
    if (!tmp) return;
    for (int y = 0; y < d->h / 2; y++) {
        uint8_t *a = rgb + (size_t)y * row, *b = rgb + (size_t)(d->h - 1 - y) * row;
        memcpy(tmp, a, row);
        memcpy(a, b, row);
        memcpy(b, tmp, row);
    }
    free(tmp);
}
