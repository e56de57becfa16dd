/*
 * glfw_forest — a minimal host engine around libtclod: GLFW and OpenGL draw the
 * thesis's terrain and forest ([Thesis8 §8.4], examples/scenes/thesis_scene.h) as
 * libtclod selects it, every frame, so that frames take a target time.
 *
 * Every frame the host
 *  1. moves the camera (a scripted flyover, or free flight),
 *  2. asks the calibration for the budget that fits the target frame time
 *     (tclod_calib_budget) and selects with it (tclod_select); with --morph the
 *     geomorph scheduler selects ahead instead, a slice each frame, and hands
 *     over a draw list of morphing patches and moving tree resolutions,
 *  3. draws the selected terrain cut (quadtree patches of 33 × 33 vertices) and
 *     the selected tree groups as point splats: a group at resolution r draws
 *     r · N · THESIS_SPLATS_PER_TREE splats for its N trees, in view or not, a
 *     prefix of every tree's splat template, or one splat for only that many of
 *     its trees while that is less than one a tree — what the cost model (thesis
 *     eq. 8.18) predicts; the patches' skirts are the one thing drawn beyond the
 *     model, the same for every patch,
 *  4. measures the time the drawing took (GL_TIME_ELAPSED queries, read a frame or
 *     two later; CPU time around glFinish where there are none, and on software
 *     renderers, whose queries do not time the rasterisation) and reports it with
 *     what the frame drew to the calibration: by default the learned cost model
 *     (tclod_calib_report_features with the draws, strip vertices and splats it
 *     sent and the framebuffer's pixels, whose render time per unit the model
 *     learns and the selector prices the next frame's nodes with), or with
 *     --cost-model scale the frame's predicted cost (tclod_calib_report).
 * Before the first frame one unmeasured draw lets the driver compile its shaders,
 * and one measured selection gives the calibration its starting scale.
 * A HUD shows the frame time against the target as a scrolling graph, the budget,
 * the solver and the selection time. Keys change the target and the solver.
 *
 * --frames N --screenshot FILE.ppm renders N frames of the flyover at a fixed
 * 60 Hz flight step (the views do not depend on the machine's speed; the detail
 * drawn does, through the measured times), writes the last one and exits 0; 77
 * means no display or no usable OpenGL context. At exit (Ctrl-C included) it
 * prints
 *
 *   summary: frames=N mean_ms=M target_ms=T avg_err=E p95_err=P mean_ratio=R
 *
 * with E the mean over the frames of |t_frame − T_frame| / T_frame, t_frame the
 * wall-clock time of a whole frame (selection, drawing, HUD and buffer swap) and
 * T_frame the target in force then; T is the target at exit; P the 95th
 * percentile (nearest rank) of that error, R the mean of t_frame / T_frame,
 * and J (jitter=J, last) the median of |t_frame − t_previous| / T_frame: how
 * much consecutive frames differ, which no budget can take out (a renderer
 * whose frame times scatter by a standard deviation s about what it was asked
 * for has J ≈ 0.95 s and an avg_err of at least about 0.8 s ≈ 0.84 J;
 * docs/calibration.md).
 * --csv FILE writes a row per frame (usage() lists the columns).
 *
 * Plain OpenGL 1.5 (vertex buffers, fixed function), what Mesa's llvmpipe draws
 * reliably; timer queries where the context has them (GL 3.3 or ARB_timer_query).
 */
#define GLFW_INCLUDE_GLEXT
#include <GLFW/glfw3.h>

#include <math.h>
#include <signal.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <tclod/tclod.h>

#include "thesis_scene.h"

#define PI 3.14159265358979323846
/* ctest's SKIP_RETURN_CODE: no display, or no OpenGL context that can draw this. */
#define EXIT_SKIP 77
/* One loop of the thesis scene's path, as flyover_sim flies it: about 260 m/s. */
#define LOOP_SECONDS 750.0
/* Where on the loop the flyover starts: towards a forested hill. */
#define FLIGHT_START 0.4
/* Height above the terrain's smooth upper envelope (thesis_camera_at), m, and
 * pitch below the horizon, radians. */
#define FLIGHT_ALTITUDE 60.0f
#define FLIGHT_PITCH 0.2f
/* The tree groups' benefit weight k ([Thesis8 eq. 8.20]). The thesis's k = 50 makes
 * a tree worth so much more than the ground that at a small budget (a software
 * renderer's) the terrain stays one patch while any tree is in view; this host
 * values its ground more. */
#define TREE_WEIGHT 10.0
/* Flight step of a headless run, s: 60 Hz whatever the machine. */
#define HEADLESS_STEP (1.0 / 60.0)
/* The window's size (it may be resized), pixels. */
#define WINDOW_WIDTH 1280
#define WINDOW_HEIGHT 720
#define DEFAULT_TARGET_MS 50.0
#define MIN_TARGET_MS 5.0
#define MAX_TARGET_MS 500.0
/* The probe that measures the calibration's starting scale selects with this
 * share of the target as its budget. */
#define PROBE_SHARE 0.2
/* --hold: frames selected (and calibrated) before the selection is kept. */
#define HOLD_AFTER 60ul
/* --morph: the share of the target frame time each frame gives the scheduler's
 * pending selection. */
#define SLICE_SHARE 0.1
/* Timer queries in flight; a result is read when it is ready, at most this late. */
#define QUERY_RING 4
/* Frames shown by the HUD's graph. */
#define GRAPH_FRAMES 256
/* Terrain patches whose vertices are kept in one vertex buffer; the least recently
 * drawn are rebuilt when needed. More than a frame's cut ever holds at sane targets;
 * a cut larger than this is still drawn, its extra patches one by one through a
 * scratch slot. */
#define PATCH_SLOTS 2048u
/* Patches morphing in one frame at most (--morph); more are drawn unmorphed. */
#define MORPH_SLOTS 512u
/* Vertices of a patch: the 33 × 33 grid and a skirt of 33 below each edge that
 * hides the cracks where a patch meets a coarser neighbour. */
#define GRID_SIDE (THESIS_PATCH_CELLS + 1u)
#define PATCH_VERTS (GRID_SIDE * GRID_SIDE + 4u * GRID_SIDE)
/* Point splats of one tree of height 1 cover about 2.5 × its crown's outline
 * (0.17 h²) when the shell's back and front both show: diameter
 * sqrt(2.5 · 0.17) · H / sqrt(k) for k splats over H pixels of height, and never
 * more than the crown's width. */
#define SPLAT_SCALE 0.65

/* The learned cost model's features (docs/calibration.md, the learned cost):
 * the thesis scene's draws, strip vertices and splats, which its nodes and
 * tree groups have, then the framebuffer's pixels, which only the frame has
 * (clearing, filling the ground: work no node's choice changes). */
#define FOREST_PIXELS THESIS_FEATURES
#define FOREST_FEATURES (THESIS_FEATURES + 1)

static const char *const forest_feature_names[FOREST_FEATURES] = {"draws", "vertices", "splats",
                                                                  "pixels"};

static const float sky_colour[3] = {0.64f, 0.76f, 0.90f};

/* ------------------------------------------------------------------------- */
/* Options                                                                   */
/* ------------------------------------------------------------------------- */

typedef struct options {
    unsigned long frames; /* 0: until the window closes */
    const char *screenshot;
    double target_ms;
    tclod_solver solver;
    int timer; /* a timer_mode */
    int morph; /* draw the geomorph scheduler's lists instead of selecting */
    int scale; /* --cost-model scale: the one-ratio calibration */
    int hold;  /* --hold: the camera stands; from HOLD_AFTER frames on, so does the selection */
    const char *csv;
} options;

/* in the order of timer_names */
typedef enum timer_mode { TIMER_AUTO, TIMER_GPU, TIMER_CPU } timer_mode;

static const char *const solver_names[] = {"greedy", "mixed", "robin_hood"};
static const char *const timer_names[] = {"auto", "gpu", "cpu"};

/* The index of v among the three names, or -1. */
static int find_name(const char *v, const char *const names[3]) {
    int k;
    for (k = 0; k < 3 && strcmp(v, names[k]); ++k)
        ;
    return k < 3 ? k : -1;
}

static void usage(FILE *out) {
    fprintf(out,
            "usage: glfw_forest [--frames N [--screenshot FILE.ppm]] [--target-ms T]\n"
            "                   [--solver greedy|mixed|robin_hood] [--timer auto|gpu|cpu]\n"
            "                   [--morph] [--cost-model features|scale] [--csv FILE] [--hold]\n"
            "                   [--help]\n"
            "\n"
            "Flies over the thesis's 120 km terrain with 1.4 million point-splat trees,\n"
            "drawing what libtclod selects every frame so that frames take T ms.\n"
            "\n"
            "  --frames N         render N frames (a fixed 60 Hz flight step), then exit\n"
            "  --screenshot FILE  with --frames: write the last frame as a binary PPM\n"
            "  --target-ms T      target frame time, %g <= T <= %g (default %g)\n"
            "  --solver S         selection algorithm (default mixed; greedy draws no trees)\n"
            "  --timer M          how the drawing is timed: gpu = GL_TIME_ELAPSED queries,\n"
            "                     cpu = CPU time around glFinish, auto = gpu where the\n"
            "                     context has them, except on software renderers (default)\n"
            "  --morph            select ahead with the geomorph scheduler and draw its\n"
            "                     transitions (terrain patches morph, trees fade); its\n"
            "                     calibration is the scale\n"
            "  --hold             the camera stands still and, after 60 frames, the\n"
            "                     selection too: the same frame is drawn again and again,\n"
            "                     and jitter measures the renderer's own scatter\n"
            "  --cost-model M     features (default): the learned cost model, nodes priced\n"
            "                     by learned ms per draw, vertex and splat and the frame by\n"
            "                     its pixels; scale: one ratio measured / predicted\n"
            "  --csv FILE         a row per frame: frame,target_ms,frame_ms,render_ms,\n"
            "                     logic_ms,predicted_ms,budget_ms,draws,vertices,splats,\n"
            "                     pixels,select_ms (predicted_ms the frame's predicted\n"
            "                     render time, budget_ms what its nodes could spend)\n"
            "\n"
            "Keys: +/- target time, Tab solver, F free flight (WASD, Q/E down/up, drag the\n"
            "left mouse button to look, Shift faster), Esc quit.\n"
            "Exit status 77: no display or no usable OpenGL context.\n",
            MIN_TARGET_MS, MAX_TARGET_MS, DEFAULT_TARGET_MS);
}

/* 0 ok, 1 --help, 2 bad usage. */
static int parse_options(int argc, char **argv, options *o) {
    int i;
    memset(o, 0, sizeof(*o));
    o->target_ms = DEFAULT_TARGET_MS;
    o->solver = TCLOD_SOLVER_MIXED;
    for (i = 1; i < argc; ++i) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        char *end = NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h"))
            return 1;
        if (!strcmp(a, "--morph")) {
            o->morph = 1;
            continue;
        }
        if (!strcmp(a, "--hold")) {
            o->hold = 1;
            continue;
        }
        if (!v) {
            fprintf(stderr, "glfw_forest: unknown option or missing value: %s\n", a);
            return 2;
        }
        ++i;
        if (!strcmp(a, "--frames")) {
            o->frames = strtoul(v, &end, 10);
            if (*v == '-' || *end || o->frames == 0) {
                fprintf(stderr, "glfw_forest: --frames needs a number >= 1\n");
                return 2;
            }
        } else if (!strcmp(a, "--screenshot")) {
            o->screenshot = v;
        } else if (!strcmp(a, "--csv")) {
            o->csv = v;
        } else if (!strcmp(a, "--cost-model")) {
            if (strcmp(v, "features") && strcmp(v, "scale")) {
                fprintf(stderr, "glfw_forest: --cost-model needs features or scale\n");
                return 2;
            }
            o->scale = !strcmp(v, "scale");
        } else if (!strcmp(a, "--target-ms")) {
            o->target_ms = strtod(v, &end);
            if (*end || !(o->target_ms >= MIN_TARGET_MS && o->target_ms <= MAX_TARGET_MS)) {
                fprintf(stderr, "glfw_forest: --target-ms needs %g..%g\n", MIN_TARGET_MS,
                        MAX_TARGET_MS);
                return 2;
            }
        } else if (!strcmp(a, "--solver")) {
            int s = find_name(v, solver_names);
            if (s < 0) {
                fprintf(stderr, "glfw_forest: unknown solver %s\n", v);
                return 2;
            }
            o->solver = (tclod_solver)s;
        } else if (!strcmp(a, "--timer")) {
            o->timer = find_name(v, timer_names);
            if (o->timer < 0) {
                fprintf(stderr, "glfw_forest: --timer needs auto, gpu or cpu\n");
                return 2;
            }
        } else {
            fprintf(stderr, "glfw_forest: unknown option %s\n", a);
            return 2;
        }
    }
    if (o->screenshot && o->frames == 0) {
        fprintf(stderr, "glfw_forest: --screenshot needs --frames\n");
        return 2;
    }
    return 0;
}

/* ------------------------------------------------------------------------- */
/* OpenGL beyond 1.1: loaded through GLFW                                    */
/* ------------------------------------------------------------------------- */

typedef struct gl_ext {
    PFNGLGENBUFFERSPROC GenBuffers;
    PFNGLDELETEBUFFERSPROC DeleteBuffers;
    PFNGLBINDBUFFERPROC BindBuffer;
    PFNGLBUFFERDATAPROC BufferData;
    PFNGLBUFFERSUBDATAPROC BufferSubData;
    /* timer queries; NULL where the context has none */
    PFNGLGENQUERIESPROC GenQueries;
    PFNGLDELETEQUERIESPROC DeleteQueries;
    PFNGLBEGINQUERYPROC BeginQuery;
    PFNGLENDQUERYPROC EndQuery;
    PFNGLGETQUERYOBJECTIVPROC GetQueryObjectiv;
    PFNGLGETQUERYOBJECTUI64VPROC GetQueryObjectui64v;
} gl_ext;

/* A software rasteriser (Mesa's llvmpipe, softpipe, swrast) runs the draws in
 * its own threads when the frame is flushed, after the commands that a timer
 * query brackets: its GL_TIME_ELAPSED times the submission, not the drawing. */
static int software_renderer(void) {
    const char *r = (const char *)glGetString(GL_RENDERER);
    return r && (strstr(r, "llvmpipe") || strstr(r, "softpipe") || strstr(r, "swrast"));
}

/* 1 when the vertex-buffer functions exist (GL 1.5); timer queries are optional. */
static int load_gl(gl_ext *gl, int want_timer) {
    int major = glfwGetWindowAttrib(glfwGetCurrentContext(), GLFW_CONTEXT_VERSION_MAJOR);
    int minor = glfwGetWindowAttrib(glfwGetCurrentContext(), GLFW_CONTEXT_VERSION_MINOR);
    memset(gl, 0, sizeof(*gl));
    if (major < 1 || (major == 1 && minor < 5))
        return 0;
    gl->GenBuffers = (PFNGLGENBUFFERSPROC)glfwGetProcAddress("glGenBuffers");
    gl->DeleteBuffers = (PFNGLDELETEBUFFERSPROC)glfwGetProcAddress("glDeleteBuffers");
    gl->BindBuffer = (PFNGLBINDBUFFERPROC)glfwGetProcAddress("glBindBuffer");
    gl->BufferData = (PFNGLBUFFERDATAPROC)glfwGetProcAddress("glBufferData");
    gl->BufferSubData = (PFNGLBUFFERSUBDATAPROC)glfwGetProcAddress("glBufferSubData");
    if (!gl->GenBuffers || !gl->DeleteBuffers || !gl->BindBuffer || !gl->BufferData ||
        !gl->BufferSubData)
        return 0;
    if (want_timer &&
        (major > 3 || (major == 3 && minor >= 3) || glfwExtensionSupported("GL_ARB_timer_query"))) {
        gl->GenQueries = (PFNGLGENQUERIESPROC)glfwGetProcAddress("glGenQueries");
        gl->DeleteQueries = (PFNGLDELETEQUERIESPROC)glfwGetProcAddress("glDeleteQueries");
        gl->BeginQuery = (PFNGLBEGINQUERYPROC)glfwGetProcAddress("glBeginQuery");
        gl->EndQuery = (PFNGLENDQUERYPROC)glfwGetProcAddress("glEndQuery");
        gl->GetQueryObjectiv = (PFNGLGETQUERYOBJECTIVPROC)glfwGetProcAddress("glGetQueryObjectiv");
        gl->GetQueryObjectui64v =
            (PFNGLGETQUERYOBJECTUI64VPROC)glfwGetProcAddress("glGetQueryObjectui64v");
        if (!gl->GenQueries || !gl->DeleteQueries || !gl->BeginQuery || !gl->EndQuery ||
            !gl->GetQueryObjectiv || !gl->GetQueryObjectui64v)
            gl->GenQueries = NULL;
    }
    return 1;
}

/* Vertex-buffer offsets travel through the pointer arguments of GL 1.1's calls. */
static const GLvoid *buffer_offset(size_t bytes) {
    return (const GLvoid *)(uintptr_t)bytes;
}

/* ------------------------------------------------------------------------- */
/* Terrain: the cut's patches, built on demand into a cache of slots         */
/* ------------------------------------------------------------------------- */

typedef struct vertex {
    float pos[3];
    uint8_t rgba[4];
} vertex;

typedef struct terrain_cache {
    GLuint vbo, ibo;
    GLsizei index_count;
    uint32_t slots;       /* cached patches: PATCH_SLOTS or fewer; the vertex buffer holds
                             them, a scratch slot after them and MORPH_SLOTS more */
    uint32_t used;        /* slots 0 .. used - 1 hold a patch */
    int32_t *slot_of;     /* per node: its slot, or -1 */
    tclod_id *node_in;    /* per slot: its node, or TCLOD_NONE */
    uint32_t *stamp;      /* per slot: the last frame that drew it */
    vertex *scratch;      /* one patch being built */
    float *heights;       /* (GRID_SIDE + 2)² samples: the grid and a border for normals */
    uint32_t morph_count; /* --morph: this frame's morphing patches, after the scratch slot */
    tclod_id *plain;      /* --morph: node_count, the draw list's patches drawn as they are */
} terrain_cache;

static double mix(double a, double b, double t) {
    return a + (b - a) * t;
}

static double smoothstep(double e0, double e1, double x) {
    double t = (x - e0) / (e1 - e0);
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    return t * t * (3.0 - 2.0 * t);
}

static uint8_t to_byte(double c) {
    return (uint8_t)(c <= 0.0 ? 0.0 : c >= 1.0 ? 255.0 : c * 255.0 + 0.5);
}

/* Meadows low down, darker grass higher, rock on steep or high ground, snow on
 * flat summits, and a darker forest floor inside the forest regions (forest > 0),
 * so that forests the budget leaves without trees still read as forest; lit by
 * a low sun from the south-east, which brings out the hills. */
static void terrain_colour(double rel, double forest, const double n[3], uint8_t out[4]) {
    static const double low[3] = {0.62, 0.66, 0.36}, mid[3] = {0.48, 0.56, 0.30},
                        high[3] = {0.52, 0.50, 0.34}, rock[3] = {0.56, 0.53, 0.48},
                        snow[3] = {0.95, 0.96, 0.98}, floor_[3] = {0.25, 0.33, 0.16};
    static const double sun[3] = {0.64, 0.42, 0.64}; /* 25 degrees above the horizon */
    double t_mid = smoothstep(0.15, 0.35, rel), t_high = smoothstep(0.40, 0.55, rel);
    double t_rock = smoothstep(0.60, 0.72, rel) + smoothstep(0.94, 0.85, n[1]);
    double t_snow = smoothstep(0.74, 0.80, rel) * smoothstep(0.80, 0.92, n[1]);
    double t_forest = smoothstep(-0.02, 0.06, forest) * (1.0 - t_snow);
    double lit = n[0] * sun[0] + n[1] * sun[1] + n[2] * sun[2];
    double shade = 0.40 + 1.40 * (lit > 0.0 ? lit : 0.0);
    int k;
    if (t_rock > 1.0)
        t_rock = 1.0;
    for (k = 0; k < 3; ++k) {
        double c = mix(mix(low[k], mid[k], t_mid), high[k], t_high);
        c = mix(mix(mix(c, rock[k], t_rock), floor_[k], t_forest), snow[k], t_snow);
        out[k] = to_byte(c * shade);
    }
    out[3] = 255;
}

/* The grid vertex that skirt vertex k (0 .. 4 · GRID_SIDE - 1, after the grid's
 * vertices) hangs below: the edges z = 0, z = end, x = 0, x = end in turn. */
static uint32_t skirt_top(uint32_t k) {
    uint32_t e = k / GRID_SIDE, i = k % GRID_SIDE;
    uint32_t gi = e < 2u ? i : (e == 2u ? 0u : GRID_SIDE - 1u);
    uint32_t gj = e < 2u ? (e == 0u ? 0u : GRID_SIDE - 1u) : i;
    return gj * GRID_SIDE + gi;
}

/* The patch's 33 × 33 vertices with colours from height, slope and sun, and its
 * skirts, into c->scratch: what every patch of any depth sends, 2112 strip
 * vertices ([Thesis8 eq. 8.19]), at its own spacing, plus the skirts' 264.
 * weight < 1 geomorphs it ([GEO §4.3]) towards its parent: every height lies
 * between its own and the parent's surface at that vertex (weight 1 = the patch
 * itself). The parent's vertices are the patch's even ones; the others lie on
 * the parent's cell edges (the mean of the two ends) or on the diagonal its
 * strips cut each cell along, from (i - 1, j + 1) to (i + 1, j - 1). */
static void build_patch(const thesis_scene *t, terrain_cache *c, tclod_id id, float weight) {
    const ptrdiff_t s = GRID_SIDE + 2u;
    uint32_t ix, iz, level, i, j, k;
    double size, cell, x0, z0, skirt;
    thesis_patch_cell(t, id, &level, &ix, &iz);
    size = (double)t->side / (double)(1u << level);
    cell = size / (double)THESIS_PATCH_CELLS;
    x0 = (double)ix * size;
    z0 = (double)iz * size;
    /* deeper than the largest step a finer neighbour's edge can make against
     * this patch's straight edge on these slopes */
    skirt = 0.25 * cell + 2.0;
    for (j = 0; j < (uint32_t)s; ++j)
        for (i = 0; i < (uint32_t)s; ++i)
            c->heights[j * s + i] =
                thesis_terrain_height((float)(x0 + ((double)i - 1.0) * cell),
                                      (float)(z0 + ((double)j - 1.0) * cell), t->side, t->height);
    for (j = 0; j < GRID_SIDE; ++j) {
        for (i = 0; i < GRID_SIDE; ++i) {
            const float *h = c->heights + (j + 1u) * s + (i + 1u);
            vertex *v = c->scratch + j * GRID_SIDE + i;
            float coarse = (i % 2u == 0u && j % 2u == 0u) ? h[0]
                           : j % 2u == 0u                 ? 0.5f * (h[-1] + h[1])
                           : i % 2u == 0u                 ? 0.5f * (h[-s] + h[s])
                                                          : 0.5f * (h[s - 1] + h[1 - s]);
            double n[3], len;
            n[0] = -((double)h[1] - (double)h[-1]) / (2.0 * cell);
            n[1] = 1.0;
            n[2] = -((double)h[s] - (double)h[-s]) / (2.0 * cell);
            len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            n[0] /= len;
            n[1] /= len;
            n[2] /= len;
            v->pos[0] = (float)(x0 + (double)i * cell);
            v->pos[1] = weight * h[0] + (1.0f - weight) * coarse;
            v->pos[2] = (float)(z0 + (double)j * cell);
            terrain_colour(t->height > 0.0f ? (double)h[0] / (double)t->height : 0.0,
                           (double)thesis_forest_mask(t, v->pos[0], v->pos[2]), n, v->rgba);
        }
    }
    for (k = 0; k < 4u * GRID_SIDE; ++k) {
        vertex *v = c->scratch + GRID_SIDE * GRID_SIDE + k;
        *v = c->scratch[skirt_top(k)];
        v->pos[1] -= (float)skirt;
    }
}

/* One index list for every patch: the 32 row strips and 4 skirt strips joined into
 * one triangle strip by repeating the last and first index of neighbouring strips
 * (degenerate triangles; every strip has an even length, so winding is kept). */
static GLsizei patch_indices(GLushort *out) {
    GLsizei n = 0;
    uint32_t j, i, k;
    for (j = 0; j < THESIS_PATCH_CELLS; ++j) {
        if (n > 0) {
            out[n] = out[n - 1];
            out[n + 1] = (GLushort)(j * GRID_SIDE);
            n += 2;
        }
        for (i = 0; i < GRID_SIDE; ++i) {
            out[n++] = (GLushort)(j * GRID_SIDE + i);
            out[n++] = (GLushort)((j + 1u) * GRID_SIDE + i);
        }
    }
    for (k = 0; k < 4u * GRID_SIDE; ++k) {
        GLushort top = (GLushort)skirt_top(k);
        if (k % GRID_SIDE == 0u) {
            out[n] = out[n - 1];
            out[n + 1] = top;
            n += 2;
        }
        out[n++] = top;
        out[n++] = (GLushort)(GRID_SIDE * GRID_SIDE + k);
    }
    return n;
}

static int terrain_init(terrain_cache *c, const gl_ext *gl, const thesis_scene *t) {
    GLushort indices[40u * 2u * GRID_SIDE + 128u];
    uint32_t i;
    memset(c, 0, sizeof(*c));
    c->slots = t->node_count < PATCH_SLOTS ? t->node_count : PATCH_SLOTS;
    c->slot_of = (int32_t *)malloc(t->node_count * sizeof(int32_t));
    c->node_in = (tclod_id *)malloc((c->slots + 1u) * sizeof(tclod_id));
    c->stamp = (uint32_t *)calloc(c->slots + 1u, sizeof(uint32_t));
    c->scratch = (vertex *)malloc(PATCH_VERTS * sizeof(vertex));
    c->heights = (float *)malloc((GRID_SIDE + 2u) * (GRID_SIDE + 2u) * sizeof(float));
    c->plain = (tclod_id *)malloc(t->node_count * sizeof(tclod_id));
    if (!c->slot_of || !c->node_in || !c->stamp || !c->scratch || !c->heights || !c->plain)
        return 0;
    for (i = 0; i < t->node_count; ++i)
        c->slot_of[i] = -1;
    for (i = 0; i <= c->slots; ++i)
        c->node_in[i] = TCLOD_NONE;
    c->index_count = patch_indices(indices);
    gl->GenBuffers(1, &c->vbo);
    gl->GenBuffers(1, &c->ibo);
    gl->BindBuffer(GL_ARRAY_BUFFER, c->vbo);
    gl->BufferData(
        GL_ARRAY_BUFFER,
        (GLsizeiptr)((size_t)(c->slots + 1u + MORPH_SLOTS) * PATCH_VERTS * sizeof(vertex)), NULL,
        GL_DYNAMIC_DRAW);
    gl->BindBuffer(GL_ELEMENT_ARRAY_BUFFER, c->ibo);
    gl->BufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)((size_t)c->index_count * sizeof(GLushort)),
                   indices, GL_STATIC_DRAW);
    gl->BindBuffer(GL_ARRAY_BUFFER, 0);
    gl->BindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
    return 1;
}

static void terrain_free(terrain_cache *c, const gl_ext *gl) {
    if (c->vbo)
        gl->DeleteBuffers(1, &c->vbo);
    if (c->ibo)
        gl->DeleteBuffers(1, &c->ibo);
    free(c->plain);
    free(c->slot_of);
    free(c->node_in);
    free(c->stamp);
    free(c->scratch);
    free(c->heights);
    memset(c, 0, sizeof(*c));
}

/* c->scratch into slot `slot` of the vertex buffer, which is bound. */
static void upload_patch(terrain_cache *c, const gl_ext *gl, size_t slot) {
    gl->BufferSubData(GL_ARRAY_BUFFER, (GLintptr)(slot * PATCH_VERTS * sizeof(vertex)),
                      (GLsizeiptr)(PATCH_VERTS * sizeof(vertex)), c->scratch);
}

/* Builds the cut's missing patches before the drawing is timed: building is the
 * host's logic, not render time. Slots fill in order; once all are used, a
 * missing patch replaces the least recently drawn one (stamps are frame + 1, so
 * 0 is never). A patch that finds every slot taken by this frame's cut stays
 * out (-1) and is built when drawn. */
static void terrain_prepare(terrain_cache *c, const gl_ext *gl, const thesis_scene *t,
                            const tclod_id *ids, size_t n, uint32_t frame) {
    size_t k;
    uint32_t now = frame + 1u;
    gl->BindBuffer(GL_ARRAY_BUFFER, c->vbo);
    for (k = 0; k < n; ++k) {
        tclod_id id = ids[k];
        uint32_t s, slot = c->slots;
        if (c->slot_of[id] >= 0) {
            c->stamp[c->slot_of[id]] = now;
            continue;
        }
        if (c->used < c->slots) {
            slot = c->used++;
        } else {
            for (s = 0; s < c->slots; ++s)
                if (c->stamp[s] != now && (slot == c->slots || c->stamp[s] < c->stamp[slot]))
                    slot = s;
            if (slot == c->slots)
                continue;
            c->slot_of[c->node_in[slot]] = -1;
        }
        build_patch(t, c, id, 1.0f);
        upload_patch(c, gl, slot);
        c->node_in[slot] = id;
        c->slot_of[id] = (int32_t)slot;
        c->stamp[slot] = now;
    }
    gl->BindBuffer(GL_ARRAY_BUFFER, 0);
}

/* Splits a draw list of the scheduler into the patches drawn as they are (into
 * plain, from the cache) and those that morph, built now into the slots after
 * the scratch slot, before the drawing is timed; past MORPH_SLOTS a morphing
 * patch is drawn as it is. */
static size_t morph_prepare(terrain_cache *c, const gl_ext *gl, const thesis_scene *t,
                            const tclod_draw *items, size_t n, tclod_id *plain) {
    size_t k, n_plain = 0;
    c->morph_count = 0;
    gl->BindBuffer(GL_ARRAY_BUFFER, c->vbo);
    for (k = 0; k < n; ++k) {
        if (items[k].fine == items[k].coarse || items[k].weight >= 1.0f ||
            c->morph_count == MORPH_SLOTS) {
            plain[n_plain++] = items[k].fine;
            continue;
        }
        build_patch(t, c, items[k].fine, items[k].weight < 0.0f ? 0.0f : items[k].weight);
        upload_patch(c, gl, (size_t)c->slots + 1u + c->morph_count++);
    }
    gl->BindBuffer(GL_ARRAY_BUFFER, 0);
    return n_plain;
}

/* Draws the patches ids from the cache (one that is not in it is built now, into
 * the scratch slot), then this frame's morphing patches. */
static void terrain_draw(terrain_cache *c, const gl_ext *gl, const thesis_scene *t,
                         const tclod_id *ids, size_t n) {
    size_t k;
    gl->BindBuffer(GL_ARRAY_BUFFER, c->vbo);
    gl->BindBuffer(GL_ELEMENT_ARRAY_BUFFER, c->ibo);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    for (k = 0; k < n + c->morph_count; ++k) {
        size_t slot = k >= n ? c->slots + 1u + (k - n) : (size_t)c->slot_of[ids[k]], base;
        if (k < n && c->slot_of[ids[k]] < 0) {
            build_patch(t, c, ids[k], 1.0f);
            slot = c->slots;
            upload_patch(c, gl, slot);
        }
        base = slot * PATCH_VERTS * sizeof(vertex);
        glVertexPointer(3, GL_FLOAT, sizeof(vertex), buffer_offset(base));
        glColorPointer(4, GL_UNSIGNED_BYTE, sizeof(vertex),
                       buffer_offset(base + offsetof(vertex, rgba)));
        glDrawElements(GL_TRIANGLE_STRIP, c->index_count, GL_UNSIGNED_SHORT, buffer_offset(0));
    }
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
    gl->BindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
    gl->BindBuffer(GL_ARRAY_BUFFER, 0);
}

/* ------------------------------------------------------------------------- */
/* Trees: one splat template, a prefix of it per tree                        */
/* ------------------------------------------------------------------------- */

/* THESIS_SPLATS_PER_TREE points of a conifer of height 1 standing at the origin,
 * ordered so that every prefix covers the whole tree evenly: point 0 is the
 * crown's middle (the one splat of a tree drawn with one), the others follow a
 * low-discrepancy R3 sequence (Roberts 2018) over height, angle and depth in the
 * crown's shell, a few of them on the trunk. */
static GLuint make_tree_template(const gl_ext *gl) {
    const double a1 = 0.8191725133961645, a2 = 0.6710436067037893, a3 = 0.5497004779019703;
    const double crown_base = 0.12, trunk_share = 0.03;
    vertex *v = (vertex *)malloc(THESIS_SPLATS_PER_TREE * sizeof(vertex));
    GLuint vbo = 0;
    uint32_t i;
    if (!v)
        return 0;
    v[0].pos[0] = 0.0f;
    v[0].pos[1] = 0.4f;
    v[0].pos[2] = 0.0f;
    v[0].rgba[0] = 36;
    v[0].rgba[1] = 78;
    v[0].rgba[2] = 34;
    v[0].rgba[3] = 255;
    for (i = 1; i < THESIS_SPLATS_PER_TREE; ++i) {
        double u = fmod(0.5 + a1 * i, 1.0), w = fmod(0.5 + a2 * i, 1.0);
        double d = fmod(0.5 + a3 * i, 1.0), angle = 2.0 * PI * w, y, r, light;
        double col[3];
        if (u < trunk_share) {
            y = u / trunk_share * (crown_base + 0.05);
            r = 0.02;
            col[0] = 0.30;
            col[1] = 0.22;
            col[2] = 0.14;
            light = 1.0;
        } else {
            /* height by the cone's surface area (density ∝ radius), then tiers of
             * branches: wider at the bottom of each of 7 tiers */
            double s = 1.0 - sqrt(1.0 - (u - trunk_share) / (1.0 - trunk_share));
            double tier = fmod(s * 7.0, 1.0);
            y = crown_base + (1.0 - crown_base) * s;
            r = THESIS_CROWN_RATIO * (1.0 - s) * (0.55 + 0.45 * (1.0 - tier)) * (0.6 + 0.4 * d);
            /* lighter towards the top and the tips, on the sunlit side */
            light = 0.75 + 0.35 * s + 0.25 * d + 0.25 * cos(angle - 0.8);
            col[0] = 0.11;
            col[1] = 0.27;
            col[2] = 0.10;
        }
        v[i].pos[0] = (float)(r * cos(angle));
        v[i].pos[1] = (float)y;
        v[i].pos[2] = (float)(r * sin(angle));
        v[i].rgba[0] = to_byte(col[0] * light);
        v[i].rgba[1] = to_byte(col[1] * light);
        v[i].rgba[2] = to_byte(col[2] * light);
        v[i].rgba[3] = 255;
    }
    gl->GenBuffers(1, &vbo);
    gl->BindBuffer(GL_ARRAY_BUFFER, vbo);
    gl->BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(THESIS_SPLATS_PER_TREE * sizeof(vertex)), v,
                   GL_STATIC_DRAW);
    gl->BindBuffer(GL_ARRAY_BUFFER, 0);
    free(v);
    return vbo;
}

/* The first `splats` points of the template bound by the caller, for the tree
 * tr (x, y, z, height), as splats of `size` pixels. view_d is the view matrix:
 * the model-view matrix is formed in double since world coordinates reach 120 km. */
static void draw_tree(const double view_d[16], const float tr[4], GLint splats, GLfloat size) {
    double h = (double)tr[3];
    GLfloat m[16];
    int c;
    for (c = 0; c < 3; ++c) {
        m[c] = (GLfloat)(view_d[c] * h);
        m[4 + c] = (GLfloat)(view_d[4 + c] * h);
        m[8 + c] = (GLfloat)(view_d[8 + c] * h);
        m[12 + c] = (GLfloat)(view_d[c] * (double)tr[0] + view_d[4 + c] * (double)tr[1] +
                              view_d[8 + c] * (double)tr[2] + view_d[12 + c]);
    }
    m[3] = m[7] = m[11] = 0.0f;
    m[15] = 1.0f;
    glLoadMatrixf(m);
    glPointSize(size);
    glDrawArrays(GL_POINTS, 0, splats);
}

static void trees_begin(const gl_ext *gl, GLuint vbo) {
    gl->BindBuffer(GL_ARRAY_BUFFER, vbo);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glVertexPointer(3, GL_FLOAT, sizeof(vertex), buffer_offset(0));
    glColorPointer(4, GL_UNSIGNED_BYTE, sizeof(vertex), buffer_offset(offsetof(vertex, rgba)));
    glEnable(GL_POINT_SMOOTH); /* round splats: smooth points, their soft rim cut by */
    glEnable(GL_ALPHA_TEST);   /* the alpha test, so no sorting is needed */
}

static void trees_end(const gl_ext *gl) {
    glDisable(GL_ALPHA_TEST);
    glDisable(GL_POINT_SMOOTH);
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
    gl->BindBuffer(GL_ARRAY_BUFFER, 0);
}

typedef struct tree_counts {
    uint32_t trees;
    double splats;
} tree_counts;

/* Draws smooth object obj's trees with per_tree splats each on average (r · S,
 * S = THESIS_SPLATS_PER_TREE), as the cost model counts them: below one, one
 * splat for that share of the trees, spread evenly; *carry keeps the fraction
 * from tree to tree, so nothing is lost to rounding. Every tree is drawn, in
 * view or not: the group's cost counts them all, and a host that culled them
 * would draw less than the calibration is told. Splats grow as fewer cover a
 * tree. */
static void object_trees_draw(const thesis_scene *t, const tclod_view *view,
                              const double view_d[16], tclod_id obj, double per_tree, double *carry,
                              float max_point, tree_counts *counts) {
    double focal = 0.5 * (double)view->viewport_height / tan(0.5 * (double)view->fov_y);
    uint32_t k;
    for (k = t->tree_first[obj]; k < t->tree_first[obj + 1u]; ++k) {
        const float *tr = t->tree_xyzh + 4u * (size_t)k;
        double h = (double)tr[3], dx = (double)tr[0] - (double)view->eye[0];
        double dy = (double)tr[1] + 0.4 * h - (double)view->eye[1];
        double dz = (double)tr[2] - (double)view->eye[2];
        double dist = sqrt(dx * dx + dy * dy + dz * dz), size;
        GLint splats;
        *carry += per_tree;
        splats = (GLint)floor(*carry);
        *carry -= (double)splats;
        if (splats <= 0)
            continue;
        /* never wider than the crown, which a lone splat stands for */
        size = h * focal / (dist > 1.0 ? dist : 1.0) *
               fmin(SPLAT_SCALE / sqrt((double)splats), 2.0 * THESIS_CROWN_RATIO);
        draw_tree(view_d, tr, splats,
                  size < 1.0                 ? 1.0f
                  : size > (double)max_point ? max_point
                                             : (GLfloat)size);
        counts->trees++;
        counts->splats += (double)splats;
    }
}

/* Draws the selected trees: every member of each of the n groups at its group's
 * resolution or, with a scheduler, every smooth object at the resolution the
 * scheduler gives it this frame (moving linearly while it changes). */
static tree_counts trees_draw(const thesis_scene *t, const gl_ext *gl, GLuint vbo,
                              const tclod_view *view, const double view_d[16],
                              const tclod_smooth_group *groups, size_t n,
                              const tclod_scheduler *sch, float max_point) {
    tree_counts counts = {0, 0.0};
    double carry = 0.5;
    size_t g;
    uint32_t p;
    trees_begin(gl, vbo);
    for (g = 0; g < (sch ? (size_t)t->smooth_count : n); ++g) {
        uint32_t first = sch ? (uint32_t)g : groups[g].first, count = sch ? 1u : groups[g].count;
        double r = sch ? tclod_scheduler_resolution(sch, t->smooth_order[g]) : groups[g].resolution;
        for (p = first; p < first + count && r > 0.0; ++p)
            object_trees_draw(t, view, view_d, t->smooth_order[p],
                              r * (double)THESIS_SPLATS_PER_TREE, &carry, max_point, &counts);
    }
    trees_end(gl);
    return counts;
}

/* ------------------------------------------------------------------------- */
/* Camera                                                                    */
/* ------------------------------------------------------------------------- */

typedef struct camera {
    int flying;                /* 0: the scripted flyover */
    double flight_time;        /* s along the loop */
    double pos[3], yaw, pitch; /* free flight: radians, yaw 0 = +x, pitch up */
    int dragging;
    double last_x, last_y;
} camera;

static void camera_forward(const camera *c, double f[3]) {
    f[0] = cos(c->pitch) * cos(c->yaw);
    f[1] = sin(c->pitch);
    f[2] = cos(c->pitch) * sin(c->yaw);
}

/* Column-major view matrix of view (gluLookAt's), in double. */
static void view_matrix(const tclod_view *v, double m[16]) {
    double f[3], s[3], u[3], len;
    int k;
    for (k = 0; k < 3; ++k)
        f[k] = (double)v->forward[k];
    len = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (k = 0; k < 3; ++k)
        f[k] /= len;
    s[0] = f[1] * (double)v->up[2] - f[2] * (double)v->up[1];
    s[1] = f[2] * (double)v->up[0] - f[0] * (double)v->up[2];
    s[2] = f[0] * (double)v->up[1] - f[1] * (double)v->up[0];
    len = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (k = 0; k < 3; ++k)
        s[k] /= len;
    u[0] = s[1] * f[2] - s[2] * f[1];
    u[1] = s[2] * f[0] - s[0] * f[2];
    u[2] = s[0] * f[1] - s[1] * f[0];
    for (k = 0; k < 3; ++k) {
        m[4 * k + 0] = s[k];
        m[4 * k + 1] = u[k];
        m[4 * k + 2] = -f[k];
        m[4 * k + 3] = 0.0;
    }
    m[12] = m[13] = m[14] = 0.0;
    for (k = 0; k < 3; ++k) {
        m[12] -= s[k] * (double)v->eye[k];
        m[13] -= u[k] * (double)v->eye[k];
        m[14] += f[k] * (double)v->eye[k];
    }
    m[15] = 1.0;
}

/* ------------------------------------------------------------------------- */
/* HUD: a 5 × 7 pixel font and a frame-time graph                            */
/* ------------------------------------------------------------------------- */

/* Rows top to bottom, bit 4 the leftmost pixel; lower case prints as upper case. */
static const uint8_t font[59][7] = {
    ['%' - 32] = {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03},
    ['(' - 32] = {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02},
    [')' - 32] = {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08},
    ['+' - 32] = {0x00, 0x04, 0x04, 0x1f, 0x04, 0x04, 0x00},
    [',' - 32] = {0x00, 0x00, 0x00, 0x00, 0x0c, 0x04, 0x08},
    ['-' - 32] = {0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00},
    ['.' - 32] = {0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c},
    ['/' - 32] = {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00},
    ['0' - 32] = {0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e},
    ['1' - 32] = {0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e},
    ['2' - 32] = {0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f},
    ['3' - 32] = {0x1f, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0e},
    ['4' - 32] = {0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02},
    ['5' - 32] = {0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e},
    ['6' - 32] = {0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e},
    ['7' - 32] = {0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},
    ['8' - 32] = {0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e},
    ['9' - 32] = {0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c},
    [':' - 32] = {0x00, 0x0c, 0x0c, 0x00, 0x0c, 0x0c, 0x00},
    ['=' - 32] = {0x00, 0x00, 0x1f, 0x00, 0x1f, 0x00, 0x00},
    ['A' - 32] = {0x0e, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11},
    ['B' - 32] = {0x1e, 0x11, 0x11, 0x1e, 0x11, 0x11, 0x1e},
    ['C' - 32] = {0x0e, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0e},
    ['D' - 32] = {0x1c, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1c},
    ['E' - 32] = {0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x1f},
    ['F' - 32] = {0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x10},
    ['G' - 32] = {0x0e, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0f},
    ['H' - 32] = {0x11, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11},
    ['I' - 32] = {0x0e, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e},
    ['J' - 32] = {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0c},
    ['K' - 32] = {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11},
    ['L' - 32] = {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1f},
    ['M' - 32] = {0x11, 0x1b, 0x15, 0x15, 0x11, 0x11, 0x11},
    ['N' - 32] = {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11},
    ['O' - 32] = {0x0e, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e},
    ['P' - 32] = {0x1e, 0x11, 0x11, 0x1e, 0x10, 0x10, 0x10},
    ['Q' - 32] = {0x0e, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0d},
    ['R' - 32] = {0x1e, 0x11, 0x11, 0x1e, 0x14, 0x12, 0x11},
    ['S' - 32] = {0x0f, 0x10, 0x10, 0x0e, 0x01, 0x01, 0x1e},
    ['T' - 32] = {0x1f, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04},
    ['U' - 32] = {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e},
    ['V' - 32] = {0x11, 0x11, 0x11, 0x11, 0x11, 0x0a, 0x04},
    ['W' - 32] = {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0a},
    ['X' - 32] = {0x11, 0x11, 0x0a, 0x04, 0x0a, 0x11, 0x11},
    ['Y' - 32] = {0x11, 0x11, 0x11, 0x0a, 0x04, 0x04, 0x04},
    ['Z' - 32] = {0x1f, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1f},
};

/* Text at pixel (x, y) (top left), each font pixel a scale × scale quad. */
static void hud_text(float x, float y, float scale, const char *s) {
    glBegin(GL_QUADS);
    for (; *s; ++s, x += 6.0f * scale) {
        int ch = *s >= 'a' && *s <= 'z' ? *s - 'a' + 'A' : *s, row, col;
        if (ch < 32 || ch > 'Z')
            continue;
        for (row = 0; row < 7; ++row) {
            for (col = 0; col < 5; ++col) {
                float px = x + (float)col * scale, py = y + (float)row * scale;
                if (!(font[ch - 32][row] & (0x10 >> col)))
                    continue;
                glVertex2f(px, py);
                glVertex2f(px + scale, py);
                glVertex2f(px + scale, py + scale);
                glVertex2f(px, py + scale);
            }
        }
    }
    glEnd();
}

typedef struct hud_state {
    float frame_ms[GRAPH_FRAMES]; /* ring, newest at (next - 1) */
    float target_ms[GRAPH_FRAMES];
    int next, filled;
} hud_state;

typedef struct hud_figures {
    double frame_ms, target_ms, budget, scale, logic_ms, select_us;
    const char *solver, *timer;
    int morph;
    size_t patches;
    uint32_t morphing; /* patches morphing (--morph) */
    tree_counts trees;
    int flying;
} hud_figures;

static void hud_draw(const hud_state *h, const hud_figures *f, int width, int height) {
    /* the panel fits 52 characters of text, the longest --morph line */
    const float x0 = 12.0f, y0 = 12.0f, s = 2.0f, w = 6.0f * s * 52.0f + 16.0f;
    const float gx = x0 + 8.0f, gy = y0 + 128.0f, gh = 70.0f;
    char line[128];
    double top = 2.0 * f->target_ms;
    int i;
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glOrtho(0.0, (double)width, (double)height, 0.0, -1.0, 1.0);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_FOG);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glColor4f(0.0f, 0.0f, 0.0f, 0.55f);
    glRectf(x0, y0, x0 + w, gy + gh + 10.0f);
    glDisable(GL_BLEND);

    glColor3f(1.0f, 1.0f, 1.0f);
    snprintf(line, sizeof(line), "frame %5.1f ms  target %5.1f ms (+/-)", f->frame_ms,
             f->target_ms);
    hud_text(gx, y0 + 8.0f, s, line);
    snprintf(line, sizeof(line), "budget %6.2f  scale %5.2f  logic %4.1f ms", f->budget, f->scale,
             f->logic_ms);
    hud_text(gx, y0 + 26.0f, s, line);
    snprintf(line, sizeof(line), "solver %s%s (tab)  select %.0f us", f->solver,
             f->morph ? " morph" : "", f->select_us);
    hud_text(gx, y0 + 44.0f, s, line);
    if (f->morph)
        snprintf(line, sizeof(line), "patches %u (%u morph)  trees %u  splats %.2fm",
                 (unsigned)f->patches, (unsigned)f->morphing, (unsigned)f->trees.trees,
                 f->trees.splats * 1e-6);
    else
        snprintf(line, sizeof(line), "patches %u  trees %u  splats %.2fm", (unsigned)f->patches,
                 (unsigned)f->trees.trees, f->trees.splats * 1e-6);
    hud_text(gx, y0 + 62.0f, s, line);
    snprintf(line, sizeof(line), "%s  timer %s",
             f->flying ? "free flight: wasd qe, drag (f)" : "flyover (f: fly)", f->timer);
    hud_text(gx, y0 + 80.0f, s, line);
    hud_text(gx, y0 + 100.0f, s, "frame time, target dashed, 0 - 2x target");

    /* the graph: frame times (green under the target, red over), the target line */
    glColor3f(0.35f, 0.35f, 0.35f);
    glBegin(GL_LINE_LOOP);
    glVertex2f(gx, gy);
    glVertex2f(gx + 2.0f * GRAPH_FRAMES, gy);
    glVertex2f(gx + 2.0f * GRAPH_FRAMES, gy + gh);
    glVertex2f(gx, gy + gh);
    glEnd();
    glBegin(GL_LINES);
    for (i = 0; i < h->filled; ++i) {
        int k = (h->next - h->filled + i + GRAPH_FRAMES) % GRAPH_FRAMES;
        double v = (double)h->frame_ms[k] / top;
        float x = gx + 2.0f * (float)(GRAPH_FRAMES - h->filled + i);
        if (h->frame_ms[k] > h->target_ms[k])
            glColor3f(1.0f, 0.35f, 0.3f);
        else
            glColor3f(0.4f, 1.0f, 0.45f);
        glVertex2f(x, gy + gh);
        glVertex2f(x, gy + gh - gh * (float)(v > 1.0 ? 1.0 : v));
    }
    glColor3f(1.0f, 0.9f, 0.3f);
    for (i = 0; i < GRAPH_FRAMES; i += 8) {
        glVertex2f(gx + 2.0f * (float)i, gy + 0.5f * gh);
        glVertex2f(gx + 2.0f * (float)(i + 4), gy + 0.5f * gh);
    }
    glEnd();
}

/* ------------------------------------------------------------------------- */
/* Input                                                                     */
/* ------------------------------------------------------------------------- */

typedef struct app {
    options opt;
    thesis_scene scene;
    tclod_selector *sel;
    tclod_solver solver;
    tclod_calib *calib;
    tclod_scheduler *sch; /* --morph */
    camera cam;
    int learn; /* the learned cost model: features, not --cost-model scale or --morph */
} app;

static void selector_desc(app *a, tclod_solver s, tclod_selector_desc *d) {
    tclod_selector_desc_default(d);
    d->solver = s;
    d->callbacks = thesis_callbacks(&a->scene);
    d->mixed.split_smooth = 1; /* the thesis's grouping of nearby tree sets (SplitVar) */
    if (a->learn) {            /* priced by features, at what the model learned so far */
        d->callbacks = thesis_feature_callbacks(&a->scene);
        d->feature_count = THESIS_FEATURES;
        if (a->calib)
            memcpy(d->coefficients, tclod_calib_coefficients(a->calib),
                   THESIS_FEATURES * sizeof(double));
        else
            thesis_feature_prior(&a->scene, d->coefficients);
    }
}

/* Replaces the scheduler by one selecting with a->solver, whose calibration
 * starts from initial_scale; keeps the old one on failure. The flyover moves at
 * about 260 m/s and turns slowly; free flight may be faster, which only makes
 * the predictions miss more. */
static int make_scheduler(app *a, double initial_scale) {
    tclod_selector_desc d;
    tclod_scheduler_desc sd;
    tclod_scheduler *sch;
    tclod_status st;
    selector_desc(a, a->solver, &d);
    tclod_scheduler_desc_default(&sd);
    sd.max_speed = 300.0;
    sd.max_turn_rate = 0.2;
    sd.calib.initial_scale = initial_scale;
    sd.calib.initial_measured = 1; /* a measurement: blend the first frames from it */
    st = tclod_scheduler_create(a->scene.scene, &d, &sd, NULL, &sch);
    if (st != TCLOD_OK) {
        fprintf(stderr, "glfw_forest: tclod_scheduler_create failed: %s\n",
                tclod_status_string(st));
        return 0;
    }
    tclod_scheduler_destroy(a->sch);
    a->sch = sch;
    return 1;
}

/* Replaces the selector (and the scheduler) by one with solver s; keeps the old
 * one on failure. */
static void set_solver(app *a, tclod_solver s) {
    tclod_selector_desc d;
    tclod_selector *sel;
    tclod_status st;
    selector_desc(a, s, &d);
    st = tclod_selector_create(a->scene.scene, &d, NULL, &sel);
    if (st != TCLOD_OK) {
        fprintf(stderr, "glfw_forest: the %s solver is not available: %s\n", solver_names[s],
                tclod_status_string(st));
        return;
    }
    tclod_selector_destroy(a->sel);
    a->sel = sel;
    a->solver = s;
    if (a->sch)
        make_scheduler(a, tclod_calib_scale(a->calib));
}

static void on_key(GLFWwindow *win, int key, int scancode, int action, int mods) {
    app *a = (app *)glfwGetWindowUserPointer(win);
    (void)scancode;
    (void)mods;
    if (action != GLFW_PRESS && action != GLFW_REPEAT)
        return;
    switch (key) {
    case GLFW_KEY_ESCAPE:
        glfwSetWindowShouldClose(win, GLFW_TRUE);
        break;
    case GLFW_KEY_TAB:
        if (action == GLFW_PRESS)
            set_solver(a, (tclod_solver)(((int)a->solver + 1) % 3));
        break;
    case GLFW_KEY_F:
        if (action == GLFW_PRESS && !a->cam.flying) {
            /* take over from the flyover where it is, looking where it looks */
            tclod_view v;
            thesis_camera_at(&a->scene, FLIGHT_START + a->cam.flight_time / LOOP_SECONDS, &v);
            a->cam.pos[0] = (double)v.eye[0];
            a->cam.pos[1] = (double)v.eye[1];
            a->cam.pos[2] = (double)v.eye[2];
            a->cam.yaw = atan2((double)v.forward[2], (double)v.forward[0]);
            a->cam.pitch =
                asin((double)v.forward[1] / sqrt((double)v.forward[0] * (double)v.forward[0] +
                                                 (double)v.forward[1] * (double)v.forward[1] +
                                                 (double)v.forward[2] * (double)v.forward[2]));
            a->cam.flying = 1;
        } else if (action == GLFW_PRESS) {
            a->cam.flying = 0;
        }
        break;
    default:
        break;
    }
}

/* + and - by the character typed, whatever the keyboard's layout. */
static void on_char(GLFWwindow *win, unsigned int codepoint) {
    app *a = (app *)glfwGetWindowUserPointer(win);
    if (codepoint == '+')
        a->opt.target_ms = fmin(a->opt.target_ms * 1.25, MAX_TARGET_MS);
    else if (codepoint == '-')
        a->opt.target_ms = fmax(a->opt.target_ms / 1.25, MIN_TARGET_MS);
}

static void on_mouse_button(GLFWwindow *win, int button, int action, int mods) {
    app *a = (app *)glfwGetWindowUserPointer(win);
    (void)mods;
    if (button == GLFW_MOUSE_BUTTON_LEFT) {
        a->cam.dragging = action == GLFW_PRESS;
        glfwGetCursorPos(win, &a->cam.last_x, &a->cam.last_y);
    }
}

static void on_cursor(GLFWwindow *win, double x, double y) {
    app *a = (app *)glfwGetWindowUserPointer(win);
    if (a->cam.dragging && a->cam.flying) {
        a->cam.yaw += 0.004 * (x - a->cam.last_x);
        a->cam.pitch -= 0.004 * (y - a->cam.last_y);
        if (a->cam.pitch > 1.5)
            a->cam.pitch = 1.5;
        if (a->cam.pitch < -1.5)
            a->cam.pitch = -1.5;
    }
    a->cam.last_x = x;
    a->cam.last_y = y;
}

/* This frame's view: the flyover at its time, or free flight moved by the keys
 * for dt seconds (never below the ground). */
static void update_view(app *a, GLFWwindow *win, double dt, int fb_w, int fb_h, tclod_view *v) {
    camera *c = &a->cam;
    thesis_camera_at(&a->scene, FLIGHT_START + c->flight_time / LOOP_SECONDS, v);
    if (c->flying) {
        double f[3], speed = 300.0 * dt, ground;
        int k;
        if (glfwGetKey(win, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS)
            speed *= 8.0;
        camera_forward(c, f);
        for (k = 0; k < 3; ++k) {
            double side = k == 0 ? -f[2] : k == 2 ? f[0] : 0.0;
            c->pos[k] += speed * (double)(glfwGetKey(win, GLFW_KEY_W) == GLFW_PRESS) * f[k];
            c->pos[k] -= speed * (double)(glfwGetKey(win, GLFW_KEY_S) == GLFW_PRESS) * f[k];
            c->pos[k] += speed * (double)(glfwGetKey(win, GLFW_KEY_D) == GLFW_PRESS) * side;
            c->pos[k] -= speed * (double)(glfwGetKey(win, GLFW_KEY_A) == GLFW_PRESS) * side;
        }
        c->pos[1] += speed * (double)(glfwGetKey(win, GLFW_KEY_E) == GLFW_PRESS);
        c->pos[1] -= speed * (double)(glfwGetKey(win, GLFW_KEY_Q) == GLFW_PRESS);
        ground = (double)thesis_terrain_height((float)c->pos[0], (float)c->pos[2], a->scene.side,
                                               a->scene.height);
        if (c->pos[1] < ground + 10.0)
            c->pos[1] = ground + 10.0;
        for (k = 0; k < 3; ++k) {
            v->eye[k] = (float)c->pos[k];
            v->forward[k] = (float)f[k];
        }
        v->up[0] = 0.0f;
        v->up[1] = 1.0f;
        v->up[2] = 0.0f;
    } else {
        c->flight_time += dt;
    }
    v->aspect = (float)fb_w / (float)fb_h;
    v->viewport_height = (float)fb_h;
}

/* ------------------------------------------------------------------------- */
/* Frame timing                                                              */
/* ------------------------------------------------------------------------- */

/* A frame whose render time is not known yet (timer queries come back later). */
typedef struct pending {
    GLuint query;
    int waiting;
    double predicted, frame_ms;
    double x[FOREST_FEATURES]; /* what it drew */
} pending;

typedef struct timing {
    int gpu;
    pending ring[QUERY_RING];
    int head; /* the frame being drawn */
    double last_render_ms;
} timing;

/* Reports every finished frame to the calibration, oldest first (the oldest is the
 * slot at head, about to be reused); with block, waits for it. The render time is the drawing's GPU
 * time, the logic time the rest of the frame. */
/* One frame's measurements to the calibration: its features to a learned
 * model, else its predicted cost. */
static void report_frame(tclod_calib *calib, int learn, const double *x, double predicted,
                         double render_ms, double frame_ms) {
    double logic = frame_ms > render_ms ? frame_ms - render_ms : 0.0;
    if (learn)
        tclod_calib_report_features(calib, x, render_ms, logic);
    else
        tclod_calib_report(calib, predicted, render_ms, logic);
}

static void timing_collect(timing *tm, const gl_ext *gl, tclod_calib *calib, int learn, int block) {
    int i;
    for (i = 0; i < QUERY_RING; ++i) {
        pending *p = &tm->ring[(tm->head + i) % QUERY_RING];
        GLint ready = 0;
        GLuint64 ns = 0;
        double render;
        if (!p->waiting)
            continue;
        if (!block)
            gl->GetQueryObjectiv(p->query, GL_QUERY_RESULT_AVAILABLE, &ready);
        if (!block && !ready)
            return; /* later frames finish later */
        gl->GetQueryObjectui64v(p->query, GL_QUERY_RESULT, &ns);
        render = (double)ns * 1e-6;
        report_frame(calib, learn, p->x, p->predicted, render, p->frame_ms);
        tm->last_render_ms = render;
        p->waiting = 0;
        block = 0;
    }
}

/* ------------------------------------------------------------------------- */
/* The world                                                                 */
/* ------------------------------------------------------------------------- */

typedef struct renderer {
    gl_ext gl;
    terrain_cache terrain;
    GLuint tree_vbo;
    GLfloat max_point; /* largest smooth point size, px */
} renderer;

/* Clears to the sky and sets the camera; the depth test and fog stay on for
 * the world's draws. Writes the view matrix to view_d. */
static void world_begin(const tclod_view *view, int fb_w, int fb_h, double view_d[16]) {
    GLfloat m[16], h = view->near_z * tanf(0.5f * view->fov_y);
    int i;
    glViewport(0, 0, fb_w, fb_h);
    glClearColor(sky_colour[0], sky_colour[1], sky_colour[2], 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glFrustum(-h * view->aspect, h * view->aspect, -h, h, view->near_z, view->far_z);
    glMatrixMode(GL_MODELVIEW);
    view_matrix(view, view_d);
    for (i = 0; i < 16; ++i)
        m[i] = (GLfloat)view_d[i];
    glLoadMatrixf(m);
    glEnable(GL_DEPTH_TEST);
    glEnable(GL_FOG);
    glFogf(GL_FOG_START, 0.25f * view->far_z);
    glFogf(GL_FOG_END, view->far_z);
}

/* Draws once, unmeasured, everything a frame draws (a patch, a tree, the HUD)
 * and shows it:
 * drivers compile their shaders at the first draw in each state, llvmpipe in
 * hundreds of milliseconds, which would otherwise land in the first frame's
 * measurement. */
static void warm_up(GLFWwindow *win, renderer *r, const thesis_scene *t, const tclod_view *view,
                    int fb_w, int fb_h) {
    static const hud_state hud;
    const tclod_id root = 0;
    double view_d[16];
    float tree[4];
    hud_figures hf;
    int k;
    terrain_prepare(&r->terrain, &r->gl, t, &root, 1, 0);
    world_begin(view, fb_w, fb_h, view_d);
    terrain_draw(&r->terrain, &r->gl, t, &root, 1);
    for (k = 0; k < 3; ++k)
        tree[k] = view->eye[k] + 100.0f * view->forward[k];
    tree[3] = 30.0f;
    trees_begin(&r->gl, r->tree_vbo);
    draw_tree(view_d, tree, 64, 4.0f);
    trees_end(&r->gl);
    memset(&hf, 0, sizeof(hf));
    hf.target_ms = 1.0;
    hf.solver = hf.timer = "";
    hud_draw(&hud, &hf, fb_w, fb_h);
    glfwSwapBuffers(win); /* the first swap sets up the window's image */
    glFinish();
}

/* The calibration's starting scale, measured: one selection at a small budget
 * drawn and timed on the CPU. The library's default scale of 1 fits the
 * thesis's graphics card; a software renderer is ten or more times slower, and
 * its first frame at scale 1 would take seconds. The patches this selection
 * builds also serve the first frames. */
static double probe_scale(app *a, renderer *r, const tclod_view *view, double budget, int fb_w,
                          int fb_h) {
    tclod_frame fr;
    tclod_stats st;
    const tclod_id *ids;
    const tclod_smooth_group *groups;
    size_t n_ids, n_groups;
    double view_d[16], t0, ms;
    memset(&fr, 0, sizeof(fr));
    fr.view = view;
    fr.budget = budget;
    if (tclod_select(a->sel, &fr, &st) != TCLOD_OK || !(st.cost > 0.0) ||
        tclod_selector_cut(a->sel, &ids, &n_ids) != TCLOD_OK ||
        tclod_selector_smooth_groups(a->sel, &groups, &n_groups) != TCLOD_OK)
        return 1.0;
    terrain_prepare(&r->terrain, &r->gl, &a->scene, ids, n_ids, 0);
    world_begin(view, fb_w, fb_h, view_d);
    glFinish();
    t0 = glfwGetTime();
    terrain_draw(&r->terrain, &r->gl, &a->scene, ids, n_ids);
    trees_draw(&a->scene, &r->gl, r->tree_vbo, view, view_d, groups, n_groups, NULL, r->max_point);
    glFinish();
    ms = (glfwGetTime() - t0) * 1e3;
    return ms > 0.0 ? ms / st.cost : 1.0;
}

/* ------------------------------------------------------------------------- */
/* Screenshot                                                                */
/* ------------------------------------------------------------------------- */

/* The back buffer as a binary PPM, top row first. */
static int write_ppm(const char *path, int w, int h) {
    size_t row = (size_t)w * 3u;
    unsigned char *px = (unsigned char *)malloc(row * (size_t)h);
    FILE *f;
    int y, ok;
    if (!px)
        return 0;
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, px);
    f = fopen(path, "wb");
    ok = f != NULL;
    if (ok) {
        ok = fprintf(f, "P6\n%d %d\n255\n", w, h) > 0;
        for (y = h - 1; y >= 0 && ok; --y)
            ok = fwrite(px + (size_t)y * row, 1, row, f) == row;
        ok = fclose(f) == 0 && ok;
    }
    free(px);
    return ok;
}

/* ------------------------------------------------------------------------- */
/* Main                                                                      */
/* ------------------------------------------------------------------------- */

/* The frames' relative errors, for the summary's percentile. */
typedef struct errors {
    double *v;
    size_t n, cap;
} errors;

static int errors_add(errors *e, double x) {
    if (e->n == e->cap) {
        size_t cap = e->cap ? 2u * e->cap : 1024u;
        double *v = (double *)realloc(e->v, cap * sizeof(*v));
        if (!v)
            return 0;
        e->v = v;
        e->cap = cap;
    }
    e->v[e->n++] = x;
    return 1;
}

static int compare_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The q-quantile, nearest rank (sorts the values); 0 for none. */
static double errors_quantile(errors *e, double q) {
    size_t rank;
    if (e->n == 0)
        return 0.0;
    qsort(e->v, e->n, sizeof(*e->v), compare_double);
    rank = (size_t)ceil(q * (double)e->n);
    return e->v[(rank > 0 ? rank : 1u) - 1u];
}

/* Ctrl-C ends the loop, so that an interactive run prints its summary too. */
static volatile sig_atomic_t interrupted;

static void on_interrupt(int sig) {
    (void)sig;
    interrupted = 1;
}

static void on_glfw_error(int code, const char *text) {
    fprintf(stderr, "glfw_forest: GLFW error %d: %s\n", code, text);
}

/* Everything before the first frame: the scene, the selector, the terrain cache
 * and the tree template, one unmeasured draw, the calibration from a measured
 * starting scale and, with --morph, the scheduler. 0 after saying what failed;
 * main frees whatever was made. */
static int setup(app *a, renderer *r, GLFWwindow *win) {
    thesis_desc desc;
    tclod_calib_desc cd;
    tclod_view v;
    tclod_status st;
    GLfloat point_range[2];
    int fb_w, fb_h;

    thesis_desc_default(&desc);
    desc.keep_trees = 1;
    desc.k = TREE_WEIGHT;
    st = thesis_build(&desc, &a->scene);
    if (st != TCLOD_OK) {
        fprintf(stderr, "glfw_forest: building the scene failed: %s\n", tclod_status_string(st));
        return 0;
    }
    /* lower than the thesis's camera and looking further down, so that the
     * forest fills more of the picture */
    a->scene.path.altitude = FLIGHT_ALTITUDE;
    a->scene.path.altitude_swing = 0.5f * FLIGHT_ALTITUDE;
    a->scene.path.pitch = FLIGHT_PITCH;
    set_solver(a, a->opt.solver);
    if (!a->sel)
        return 0; /* set_solver said why */
    if (!terrain_init(&r->terrain, &r->gl, &a->scene)) {
        fprintf(stderr, "glfw_forest: out of memory for the terrain's patch cache\n");
        return 0;
    }
    r->tree_vbo = make_tree_template(&r->gl);
    if (!r->tree_vbo) {
        fprintf(stderr, "glfw_forest: out of memory for the tree template\n");
        return 0;
    }
    printf("glfw_forest: %u terrain patches, %u trees in %u groups; target %.1f ms, %s solver\n",
           a->scene.node_count, a->scene.tree_count, a->scene.smooth_count, a->opt.target_ms,
           solver_names[a->solver]);

    glGetFloatv(GL_SMOOTH_POINT_SIZE_RANGE, point_range);
    r->max_point = point_range[1] > 1.0f ? point_range[1] : 1.0f;
    glFogi(GL_FOG_MODE, GL_LINEAR);
    glFogfv(GL_FOG_COLOR, (const GLfloat[4]){sky_colour[0], sky_colour[1], sky_colour[2], 1.0f});
    glAlphaFunc(GL_GREATER, 0.5f);
    glfwGetFramebufferSize(win, &fb_w, &fb_h);
    update_view(a, win, 0.0, fb_w > 0 ? fb_w : 1, fb_h > 0 ? fb_h : 1, &v);
    warm_up(win, r, &a->scene, &v, fb_w, fb_h);

    tclod_calib_desc_default(&cd);
    cd.initial_scale = probe_scale(a, r, &v, PROBE_SHARE * a->opt.target_ms, fb_w, fb_h);
    cd.initial_measured = 1; /* a measurement: blend the first frames from it */
    if (a->learn) {          /* the thesis's prices at the probe's scale; the pixels' unknown */
        uint32_t i;
        cd.feature_count = FOREST_FEATURES;
        thesis_feature_prior(&a->scene, cd.prior);
        for (i = 0; i < FOREST_FEATURES; ++i) {
            cd.feature_names[i] = forest_feature_names[i];
            cd.prior[i] = i < THESIS_FEATURES ? cd.prior[i] * cd.initial_scale : 0.0;
        }
    }
    st = tclod_calib_create(&cd, NULL, &a->calib);
    if (st != TCLOD_OK) {
        fprintf(stderr, "glfw_forest: tclod_calib_create failed: %s\n", tclod_status_string(st));
        return 0;
    }
    printf("glfw_forest: measured %.2f ms per predicted ms to start from\n", cd.initial_scale);
    return !a->opt.morph || make_scheduler(a, cd.initial_scale);
}

int main(int argc, char **argv) {
    static app a;
    static hud_state hud;
    static renderer r;
    static timing tm;
    GLFWwindow *win;
    tclod_status st;
    double last_time, sum_ms = 0.0, sum_err = 0.0, sum_ratio = 0.0;
    errors errs = {NULL, 0, 0}, jumps = {NULL, 0, 0};
    double last_ms = 0.0;
    const tclod_id *ids = NULL; /* the selection drawn, kept from frame to frame for --hold */
    const tclod_smooth_group *groups = NULL;
    size_t n_ids = 0, n_groups = 0;
    tclod_stats kept;
    FILE *csv = NULL;
    double now = 0.0; /* the scheduler's clock: flight time, s */
    unsigned long frame = 0;
    int rc, i, fb_w, fb_h;

    rc = parse_options(argc, argv, &a.opt);
    if (rc == 1) {
        usage(stdout);
        return 0;
    }
    if (rc != 0)
        return rc;

    a.learn = !a.opt.scale && !a.opt.morph;
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit()) {
        fprintf(stderr, "glfw_forest: no display (GLFW could not start); skipped\n");
        return EXIT_SKIP;
    }
    glfwWindowHint(GLFW_DEPTH_BITS, 24);
    win = glfwCreateWindow(WINDOW_WIDTH, WINDOW_HEIGHT, "glfw_forest (libtclod)", NULL, NULL);
    if (!win) {
        fprintf(stderr, "glfw_forest: no OpenGL context could be made; skipped\n");
        glfwTerminate();
        return EXIT_SKIP;
    }
    glfwMakeContextCurrent(win);
    if (!load_gl(&r.gl,
                 a.opt.timer == TIMER_GPU || (a.opt.timer == TIMER_AUTO && !software_renderer()))) {
        fprintf(stderr, "glfw_forest: the OpenGL context lacks vertex buffers (GL 1.5); "
                        "skipped\n");
        glfwDestroyWindow(win);
        glfwTerminate();
        return EXIT_SKIP;
    }
    /* frames as fast as the work allows: the frame time is what is being controlled */
    glfwSwapInterval(0);
    printf("glfw_forest: %s, OpenGL %s, timer %s\n", (const char *)glGetString(GL_RENDERER),
           (const char *)glGetString(GL_VERSION), r.gl.GenQueries ? "GL_TIME_ELAPSED" : "CPU");
    glfwSetWindowUserPointer(win, &a);
    glfwSetKeyCallback(win, on_key);
    glfwSetCharCallback(win, on_char);
    glfwSetMouseButtonCallback(win, on_mouse_button);
    glfwSetCursorPosCallback(win, on_cursor);
    rc = setup(&a, &r, win) ? 0 : 1;
    tm.gpu = rc == 0 && r.gl.GenQueries != NULL;
    for (i = 0; tm.gpu && i < QUERY_RING; ++i)
        r.gl.GenQueries(1, &tm.ring[i].query);

    if (rc == 0 && a.opt.csv) {
        csv = fopen(a.opt.csv, "w");
        if (csv)
            fprintf(csv, "frame,target_ms,frame_ms,render_ms,logic_ms,predicted_ms,budget_ms,"
                         "draws,vertices,splats,pixels,select_ms\n");
        else {
            fprintf(stderr, "glfw_forest: cannot write %s\n", a.opt.csv);
            rc = 1;
        }
    }
    last_time = glfwGetTime();
    signal(SIGINT, on_interrupt);
    while (rc == 0 && !interrupted && !glfwWindowShouldClose(win) &&
           (a.opt.frames == 0 || frame < a.opt.frames)) {
        double start = glfwGetTime(), budget = 0.0, view_d[16], frame_ms, t0, predicted, err;
        double fixed[FOREST_FEATURES] = {0.0}, x[FOREST_FEATURES];
        double dt = a.opt.hold ? 0.0 : a.opt.frames ? HEADLESS_STEP : start - last_time;
        int last = a.opt.frames && frame + 1u == a.opt.frames;
        tclod_view view;
        tclod_frame fr;
        tclod_stats stats;
        hud_figures hf;

        last_time = start;
        glfwPollEvents();
        if (tm.gpu)
            timing_collect(&tm, &r.gl, a.calib, a.learn, tm.ring[tm.head].waiting);
        glfwGetFramebufferSize(win, &fb_w, &fb_h);
        if (fb_w <= 0 || fb_h <= 0) { /* minimised */
            glfwWaitEventsTimeout(0.1);
            continue;
        }
        dt = dt > 0.1 ? 0.1 : dt;
        now += dt;
        update_view(&a, win, dt, fb_w, fb_h, &view);
        fixed[FOREST_PIXELS] = (double)fb_w * (double)fb_h;
        memset(&stats, 0, sizeof(stats));
        hf.morphing = 0;
        if (!a.sch) {
            ids = NULL;
            groups = NULL;
            n_ids = n_groups = 0;
        }

        if (a.sch) {
            /* the scheduler: the render time that fits the target (its own
             * calibration turns it into a budget), a slice of the next selection,
             * and this frame's draw list */
            const tclod_draw *items;
            size_t n_items;
            tclod_scheduler_stats ss;
            tclod_render_budget(a.opt.target_ms, tclod_calib_logic(tclod_scheduler_calib(a.sch)),
                                1.0, &budget);
            st = tclod_scheduler_update(a.sch, now, &view, budget,
                                        SLICE_SHARE * a.opt.target_ms * 1e-3);
            if (st != TCLOD_OK) {
                fprintf(stderr, "glfw_forest: tclod_scheduler_update failed: %s\n",
                        tclod_status_string(st));
                rc = 1;
                break;
            }
            tclod_scheduler_draws(a.sch, &items, &n_items);
            tclod_scheduler_get_stats(a.sch, &ss);
            n_ids = morph_prepare(&r.terrain, &r.gl, &a.scene, items, n_items, r.terrain.plain);
            ids = r.terrain.plain;
            predicted = ss.draw_cost;
            budget = ss.budget;
            stats.solve_seconds = ss.select_seconds;
            hf.morphing = ss.morphing;
        } else {
            /* libtclod: the budget for the target frame time, the selection, the
             * result; with the learned model the nodes are priced as it learned,
             * and the budget is what the frame's pixels leave */
            if (a.learn) {
                tclod_selector_set_coefficients(a.sel, tclod_calib_coefficients(a.calib));
                tclod_calib_budget_fixed(a.calib, a.opt.target_ms, fixed, &budget);
            } else {
                tclod_calib_budget(a.calib, a.opt.target_ms, &budget);
            }
            memset(&fr, 0, sizeof(fr));
            fr.view = &view;
            fr.budget = budget;
            if (a.opt.hold && frame >= HOLD_AFTER) {
                stats = kept; /* --hold: the same selection, drawn again */
                stats.solve_seconds = 0.0;
            } else {
                st = tclod_select(a.sel, &fr, &stats);
                if (st != TCLOD_OK) {
                    fprintf(stderr, "glfw_forest: tclod_select failed: %s\n",
                            tclod_status_string(st));
                    rc = 1;
                    break;
                }
                kept = stats;
            }
            tclod_selector_cut(a.sel, &ids, &n_ids);
            tclod_selector_smooth_groups(a.sel, &groups, &n_groups);
            predicted = stats.cost + tclod_calib_predict(a.calib, fixed);
        }
        terrain_prepare(&r.terrain, &r.gl, &a.scene, ids, n_ids, (uint32_t)frame);

        /* the measured part: what the selection's predicted cost is about, the
         * draws of the selected patches and trees (clearing the screen is not) */
        world_begin(&view, fb_w, fb_h, view_d);
        if (tm.gpu)
            r.gl.BeginQuery(GL_TIME_ELAPSED, tm.ring[tm.head].query);
        else
            glFinish();
        t0 = glfwGetTime();
        terrain_draw(&r.terrain, &r.gl, &a.scene, ids, n_ids);
        hf.trees = trees_draw(&a.scene, &r.gl, r.tree_vbo, &view, view_d, groups, n_groups, a.sch,
                              r.max_point);
        if (tm.gpu) {
            r.gl.EndQuery(GL_TIME_ELAPSED);
        } else {
            glFinish();
            tm.last_render_ms = (glfwGetTime() - t0) * 1e3;
        }

        x[THESIS_DRAWS] = (double)(n_ids + r.terrain.morph_count) + (double)hf.trees.trees;
        x[THESIS_VERTICES] = (double)(n_ids + r.terrain.morph_count) * THESIS_PATCH_VERTICES;
        x[THESIS_SPLATS] = hf.trees.splats;
        x[FOREST_PIXELS] = fixed[FOREST_PIXELS];
        hf.frame_ms =
            hud.filled ? (double)hud.frame_ms[(hud.next + GRAPH_FRAMES - 1) % GRAPH_FRAMES] : 0.0;
        hf.target_ms = a.opt.target_ms;
        hf.budget = budget;
        hf.scale = tclod_calib_scale(a.sch ? tclod_scheduler_calib(a.sch) : a.calib);
        hf.logic_ms = tclod_calib_logic(a.sch ? tclod_scheduler_calib(a.sch) : a.calib);
        hf.select_us = stats.solve_seconds * 1e6;
        hf.solver = solver_names[a.solver];
        hf.morph = a.opt.morph;
        hf.timer = tm.gpu ? "gpu" : "cpu";
        hf.patches = n_ids + r.terrain.morph_count;
        hf.flying = a.cam.flying;
        hud_draw(&hud, &hf, fb_w, fb_h);
        if (last && a.opt.screenshot && !write_ppm(a.opt.screenshot, fb_w, fb_h)) {
            fprintf(stderr, "glfw_forest: cannot write %s\n", a.opt.screenshot);
            rc = 1;
        }
        glfwSwapBuffers(win);

        /* the frame's measurements go to the calibration: now with CPU timing, when
         * the query is ready with GPU timing; logic is the rest of the frame */
        frame_ms = (glfwGetTime() - start) * 1e3;
        if (tm.gpu) {
            tm.ring[tm.head].waiting = 1;
            tm.ring[tm.head].predicted = predicted;
            tm.ring[tm.head].frame_ms = frame_ms;
            memcpy(tm.ring[tm.head].x, x, sizeof x);
            tm.head = (tm.head + 1) % QUERY_RING;
        } else {
            report_frame(a.calib, a.learn, x, predicted, tm.last_render_ms, frame_ms);
        }
        /* the scheduler's own calibration, render and logic time: with GPU timing
         * the latest measured frame, a frame or two old, stands in for this one */
        if (a.sch)
            tclod_scheduler_report_frame(a.sch, tm.last_render_ms,
                                         frame_ms > tm.last_render_ms ? frame_ms - tm.last_render_ms
                                                                      : 0.0);
        hud.frame_ms[hud.next] = (float)frame_ms;
        hud.target_ms[hud.next] = (float)a.opt.target_ms;
        hud.next = (hud.next + 1) % GRAPH_FRAMES;
        if (hud.filled < GRAPH_FRAMES)
            hud.filled++;
        err = fabs(frame_ms - a.opt.target_ms) / a.opt.target_ms;
        if (csv)
            fprintf(csv, "%lu,%g,%.4f,%.4f,%.4f,%.4f,%.4f,%.0f,%.0f,%.0f,%.0f,%.4f\n", frame,
                    a.opt.target_ms, frame_ms, tm.last_render_ms,
                    frame_ms > tm.last_render_ms ? frame_ms - tm.last_render_ms : 0.0, predicted,
                    budget, x[0], x[1], x[2], x[3], stats.solve_seconds * 1e3);
        if (!errors_add(&errs, err) ||
            (frame > 0 && !errors_add(&jumps, fabs(frame_ms - last_ms) / a.opt.target_ms))) {
            fprintf(stderr, "glfw_forest: out of memory for the frame figures\n");
            rc = 1;
        }
        sum_ms += frame_ms;
        sum_err += err;
        sum_ratio += frame_ms / a.opt.target_ms;
        last_ms = frame_ms;
        ++frame;
    }

    if (frame > 0)
        printf("summary: frames=%lu mean_ms=%.3f target_ms=%.3f avg_err=%.4f p95_err=%.4f "
               "mean_ratio=%.4f jitter=%.4f\n",
               frame, sum_ms / (double)frame, a.opt.target_ms, sum_err / (double)frame,
               errors_quantile(&errs, 0.95), sum_ratio / (double)frame,
               errors_quantile(&jumps, 0.5));
    free(errs.v);
    free(jumps.v);
    if (csv && fclose(csv) != 0) {
        fprintf(stderr, "glfw_forest: cannot write %s\n", a.opt.csv);
        rc = 1;
    }
    for (i = 0; tm.gpu && i < QUERY_RING; ++i)
        r.gl.DeleteQueries(1, &tm.ring[i].query);
    r.gl.DeleteBuffers(1, &r.tree_vbo);
    terrain_free(&r.terrain, &r.gl);
    tclod_scheduler_destroy(a.sch);
    tclod_selector_destroy(a.sel);
    tclod_calib_destroy(a.calib);
    thesis_scene_free(&a.scene);
    glfwDestroyWindow(win);
    glfwTerminate();
    return rc;
}
