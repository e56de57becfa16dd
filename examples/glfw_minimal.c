/*
 * glfw_minimal — the smallest window host of libtclod (docs/example.md).
 *
 * A field of boxes, each an object with four levels of detail drawn in the colour
 * of its level (red, orange, green, blue: coarse to fine), seen by a camera that
 * circles the field. Every frame the greedy solver selects the levels that fit a
 * budget of predicted milliseconds; + and - change the budget, and the title bar
 * shows it with the selection's predicted cost. The frame loop alone, in legacy
 * OpenGL; glfw_forest is the full host (calibration, measured times, smooth objects).
 *
 * A box at level k is drawn as its own draw with its faces cut into 4^k quads, so
 * what a level costs is what it sends: the selector prices each box by its
 * features (one draw, its vertices) at coefficients per draw and per vertex.
 * --target-ms T aims at frames of T ms instead of a fixed budget: the learned
 * cost model (docs/calibration.md) learns those coefficients from the drawing's
 * measured time (CPU time around glFinish) and turns T into the budget.
 *
 * --frames N renders N frames at a fixed 60 Hz step and exits (--screenshot writes
 * the last one as a binary PPM); exit status 77 means no display or OpenGL context.
 * At exit it prints
 *   summary: frames=N budget_ms=B mean_cost_ms=C violations=V levels=a/b/c/d
 * V the frames whose predicted cost exceeded the budget (0, or the exit status is
 * 1), a..d the boxes the last frame drew at each level, coarsest first; with
 * --target-ms, then target_ms=T mean_ms=M avg_err=E: the drawing's mean time and
 * its mean |time - T| / T.
 */
#include <GLFW/glfw3.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <tclod/tclod.h>

#include "glfw_minimal.h"

#define LEVELS GLFW_MINIMAL_LEVELS
#define SIDE 24     /* boxes per row: SIDE x SIDE */
#define SPACING 5.0 /* m between boxes */
#define NODES (SIDE * SIDE * LEVELS)
#define ORBIT_RATE 0.1 /* the camera's turn around the field, rad/s */
#define PITCH 0.42     /* radians below the horizon */
#define EXIT_SKIP 77

static const double level_detail[LEVELS] = {0.25, 0.6, 0.85, 1.0};
static const int level_cells[LEVELS] = {1, 2, 4, 8}; /* a face's quads per side */
/* The price of a draw and of a vertex, ms, to start from: level costs of 0.003,
 * 0.006, 0.019 and 0.07 ms */
static const double prior_ms[2] = {0.002, 5.3e-5};
static const char *const feature_names[2] = {"draws", "vertices"};

typedef struct app {
    int level[NODES];    /* per node id: its level */
    float box[NODES][4]; /* per node id: its box's centre x, z, half width, height */
    double budget_ms;
} app;

/* The vertices a box at level k sends: 5 faces of n x n quads. */
static double level_vertices(int k) {
    return 20.0 * level_cells[k] * level_cells[k];
}

static double benefit(void *user, const tclod_query *q) {
    return q->screen_area > 0 ? level_detail[((app *)user)->level[q->id]] * q->screen_area : 0.0;
}
static void features(void *user, const tclod_query *q, double *out) {
    out[0] = 1.0; /* its draw */
    out[1] = level_vertices(((app *)user)->level[q->id]);
}

/* + and -, by the character typed whatever the keyboard's layout. */
static void on_char(GLFWwindow *win, unsigned int c) {
    app *a = (app *)glfwGetWindowUserPointer(win);
    if (c == '+' && a->budget_ms < 100.0)
        a->budget_ms *= 1.25;
    else if (c == '-' && a->budget_ms > 0.05)
        a->budget_ms /= 1.25;
}
static void on_key(GLFWwindow *win, int key, int scancode, int action, int mods) {
    (void)scancode;
    (void)mods;
    if (key == GLFW_KEY_ESCAPE && action == GLFW_PRESS)
        glfwSetWindowShouldClose(win, GLFW_TRUE);
}

/* The scene: per box a chain of LEVELS nodes, bounded by the box's sphere. */
static tclod_status build(app *a, tclod_scene *scene) {
    tclod_status st = TCLOD_OK;
    for (int i = 0; i < SIDE * SIDE && st == TCLOD_OK; ++i) {
        float x = (float)(SPACING * (i % SIDE - (SIDE - 1) / 2.0));
        float z = (float)(SPACING * (i / SIDE - (SIDE - 1) / 2.0));
        float w = 1.2f, h = 1.5f + 2.5f * (float)((i * 7919) % 101) / 100.0f; /* some height */
        float sphere[4] = {x, 0.5f * h, z, sqrtf(2.0f * w * w + 0.25f * h * h)};
        tclod_id node = TCLOD_NONE;
        for (int k = 0; k < LEVELS && st == TCLOD_OK; ++k) {
            st = tclod_scene_add_node(scene, node, sphere, &node);
            if (st == TCLOD_OK && node < NODES) {
                a->level[node] = k;
                a->box[node][0] = x, a->box[node][1] = z, a->box[node][2] = w, a->box[node][3] = h;
            }
        }
    }
    return st;
}

/* The camera at time t (s): circling the field 40 m out and 14 m up, looking
 * towards its centre and PITCH below the horizon. */
static tclod_view camera_at(double t, int width, int height) {
    double a = ORBIT_RATE * t, r = 40.0;
    tclod_view v = {.eye = {r * cos(a), 14.0, r * sin(a)},
                    .forward = {(float)(-cos(a) * cos(PITCH)), (float)-sin(PITCH),
                                (float)(-sin(a) * cos(PITCH))}, /* unit length */
                    .up = {0.0f, 1.0f, 0.0f},
                    .fov_y = 1.0f,
                    .aspect = (float)width / (float)height,
                    .near_z = 0.5f,
                    .far_z = 500.0f,
                    .viewport_height = (float)height};
    return v;
}

/* The projection and view matrices of v (forward of unit length), for the
 * fixed-function pipeline. */
static void load_camera(const tclod_view *v) {
    const float *f = v->forward, *up = v->up;
    float top = v->near_z * tanf(0.5f * v->fov_y), s[3], u[3], m[16] = {0}, len;
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glFrustum(-top * v->aspect, top * v->aspect, -top, top, v->near_z, v->far_z);
    for (int k = 0; k < 3; ++k) /* side = forward x up */
        s[k] = f[(k + 1) % 3] * up[(k + 2) % 3] - f[(k + 2) % 3] * up[(k + 1) % 3];
    len = sqrtf(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int k = 0; k < 3; ++k) /* the camera's up = side x forward */
        s[k] /= len;
    for (int k = 0; k < 3; ++k)
        u[k] = s[(k + 1) % 3] * f[(k + 2) % 3] - s[(k + 2) % 3] * f[(k + 1) % 3];
    for (int k = 0; k < 3; ++k) { /* rows side, up, -forward; then the eye's translation */
        m[4 * k] = s[k], m[4 * k + 1] = u[k], m[4 * k + 2] = -f[k];
        m[12] -= s[k] * (float)v->eye[k];
        m[13] -= u[k] * (float)v->eye[k];
        m[14] += f[k] * (float)v->eye[k];
    }
    m[15] = 1.0f;
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixf(m);
}

/* A face from corner o along edges u and v, cut into n x n quads. */
static void draw_face(const float o[3], const float u[3], const float v[3], int n) {
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            float a = (float)i / n, b = (float)j / n, d = 1.0f / n;
            float q[4][2] = {{a, b}, {a + d, b}, {a + d, b + d}, {a, b + d}};
            for (int k = 0; k < 4; ++k)
                glVertex3f(o[0] + q[k][0] * u[0] + q[k][1] * v[0],
                           o[1] + q[k][0] * u[1] + q[k][1] * v[1],
                           o[2] + q[k][0] * u[2] + q[k][1] * v[2]);
        }
}

/* One box, one draw: the top and four sides, each face a shade of its level's
 * colour and cut into level_cells[level]² quads. */
static void draw_box(const float b[4], int level) {
    static const float side[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    const unsigned char *c = glfw_minimal_colour[level];
    float x = b[0], z = b[1], w = b[2], h = b[3];
    unsigned s = glfw_minimal_shade[0];
    int n = level_cells[level];
    glBegin(GL_QUADS);
    glColor3ub((GLubyte)(c[0] * s / 4), (GLubyte)(c[1] * s / 4), (GLubyte)(c[2] * s / 4));
    draw_face((const float[3]){x - w, h, z - w}, (const float[3]){0, 0, 2 * w},
              (const float[3]){2 * w, 0, 0}, n);
    for (int k = 0; k < 4; ++k) {
        float nx = side[k][0], nz = side[k][1], tx = -nz, tz = nx; /* normal, tangent */
        s = glfw_minimal_shade[nx != 0.0f ? 1 : 2];
        glColor3ub((GLubyte)(c[0] * s / 4), (GLubyte)(c[1] * s / 4), (GLubyte)(c[2] * s / 4));
        draw_face((const float[3]){x + w * (nx - tx), 0.0f, z + w * (nz - tz)},
                  (const float[3]){2 * w * tx, 0, 2 * w * tz}, (const float[3]){0, h, 0}, n);
    }
    glEnd();
}

/* The back buffer as a binary PPM, top row first. */
static int write_ppm(const char *path, int w, int h) {
    size_t row = (size_t)w * 3u;
    unsigned char *px = (unsigned char *)malloc(row * (size_t)h);
    FILE *f = px ? fopen(path, "wb") : NULL;
    int ok = f != NULL;
    if (ok) {
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, px);
        ok = fprintf(f, "P6\n%d %d\n255\n", w, h) > 0;
        for (int y = h - 1; y >= 0 && ok; --y)
            ok = fwrite(px + (size_t)y * row, 1, row, f) == row;
    }
    if (f)
        ok = fclose(f) == 0 && ok;
    free(px);
    return ok;
}

static const char usage[] =
    "usage: glfw_minimal [--budget-ms X | --target-ms T] [--frames N [--screenshot FILE.ppm]]\n"
    "                    [--help]\n"
    "\n"
    "A field of 576 boxes of 4 levels of detail, drawn in the colour of the level the\n"
    "greedy solver selects within the budget: red, orange, green, blue, coarse to fine.\n"
    "\n"
    "  --budget-ms X      budget of predicted ms per frame, 0.05 <= X <= 100 (default 3)\n"
    "  --target-ms T      aim the drawing at T ms, 1 <= T <= 500, learning the price\n"
    "                     of a draw and a vertex from its measured time\n"
    "  --frames N         render N frames (a fixed 60 Hz step), then exit\n"
    "  --screenshot FILE  with --frames: write the last frame as a binary PPM\n"
    "Keys: + and - budget x 1.25 and / 1.25, Esc quit. Exit status 0; 1 on a failure;\n"
    "2 for a bad command line; 77 without a display or an OpenGL context.\n";

int main(int argc, char **argv) {
    static app a = {.budget_ms = 3.0};
    unsigned long frames = 0, frame = 0, violations = 0;
    double target_ms = 0.0, sum_ms = 0.0, sum_err = 0.0;
    const char *shot = NULL;
    for (int i = 1; i < argc; ++i) {
        const char *v = i + 1 < argc ? argv[i + 1] : "";
        char *end = NULL;
        if (!strcmp(argv[i], "--help")) {
            fputs(usage, stdout);
            return 0;
        } else if (!strcmp(argv[i], "--budget-ms") && (a.budget_ms = strtod(v, &end)) >= 0.05 &&
                   a.budget_ms <= 100.0 && !*end) {
            ++i;
        } else if (!strcmp(argv[i], "--target-ms") && (target_ms = strtod(v, &end)) >= 1.0 &&
                   target_ms <= 500.0 && !*end) {
            ++i;
        } else if (!strcmp(argv[i], "--frames") && *v >= '1' && *v <= '9' &&
                   (frames = strtoul(v, &end, 10)) > 0 && !*end) {
            ++i;
        } else if (!strcmp(argv[i], "--screenshot") && *v) {
            shot = argv[++i];
        } else {
            fprintf(stderr, "glfw_minimal: bad option or value: %s (try --help)\n", argv[i]);
            return 2;
        }
    }
    if (shot && !frames) {
        fprintf(stderr, "glfw_minimal: --screenshot needs --frames\n");
        return 2;
    }

    if (!glfwInit()) {
        fprintf(stderr, "glfw_minimal: no display; skipped\n");
        return EXIT_SKIP;
    }
    glfwWindowHint(GLFW_DEPTH_BITS, 24);
    GLFWwindow *win = glfwCreateWindow(1024, 640, "glfw_minimal", NULL, NULL);
    if (!win) {
        fprintf(stderr, "glfw_minimal: no OpenGL context; skipped\n");
        glfwTerminate();
        return EXIT_SKIP;
    }
    glfwMakeContextCurrent(win);
    glfwSwapInterval(frames ? 0 : 1); /* headless: as fast as it goes */
    glfwSetWindowUserPointer(win, &a);
    glfwSetCharCallback(win, on_char);
    glfwSetKeyCallback(win, on_key);
    glEnable(GL_DEPTH_TEST);

    tclod_scene *scene = NULL;
    tclod_selector *sel = NULL;
    tclod_selector_desc desc;
    tclod_selector_desc_default(&desc); /* greedy solver, warm start */
    desc.callbacks = (tclod_callbacks){.benefit = benefit, .features = features, .user = &a};
    desc.feature_count = 2;
    desc.coefficients[0] = prior_ms[0], desc.coefficients[1] = prior_ms[1];
    desc.strict = 1;
    tclod_calib *calib = NULL; /* --target-ms: the learned cost model */
    tclod_calib_desc cd;
    tclod_calib_desc_default(&cd);
    cd.feature_count = 2;
    for (int k = 0; k < 2; ++k)
        cd.prior[k] = prior_ms[k], cd.feature_names[k] = feature_names[k];
    tclod_status st = target_ms > 0.0 ? tclod_calib_create(&cd, NULL, &calib) : TCLOD_OK;
    if (st == TCLOD_OK)
        st = tclod_scene_create(NULL, &scene);
    if (st == TCLOD_OK)
        st = build(&a, scene);
    if (st == TCLOD_OK)
        st = tclod_selector_create(scene, &desc, NULL, &sel);
    int rc = st == TCLOD_OK ? 0 : 1;
    if (rc)
        fprintf(stderr, "glfw_minimal: setting up libtclod failed: %s\n", tclod_status_string(st));

    double sum_cost = 0.0;
    size_t at[LEVELS] = {0};
    while (rc == 0 && !glfwWindowShouldClose(win) && (!frames || frame < frames)) {
        int w, h;
        glfwPollEvents();
        glfwGetFramebufferSize(win, &w, &h);
        if (w <= 0 || h <= 0) { /* minimised */
            glfwWaitEventsTimeout(0.1);
            continue;
        }
        const tclod_view view = camera_at(frames ? frame / 60.0 : glfwGetTime(), w, h);
        tclod_stats stats;
        const tclod_id *ids;
        size_t n;
        if (calib) { /* the model's prices, and the budget that fits the target */
            st = tclod_selector_set_coefficients(sel, tclod_calib_coefficients(calib));
            if (st == TCLOD_OK)
                st = tclod_calib_budget(calib, target_ms, &a.budget_ms);
        }
        if (st == TCLOD_OK)
            st = tclod_select(sel, &(tclod_frame){.view = &view, .budget = a.budget_ms}, &stats);
        if (st == TCLOD_OK)
            st = tclod_selector_cut(sel, &ids, &n);
        if (st != TCLOD_OK) {
            fprintf(stderr, "glfw_minimal: selecting failed: %s\n", tclod_status_string(st));
            rc = 1;
            break;
        }
        violations += stats.cost > a.budget_ms;
        sum_cost += stats.cost;

        glViewport(0, 0, w, h);
        glClearColor(0.10f, 0.12f, 0.16f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        load_camera(&view);
        glBegin(GL_QUADS);
        glColor3ub(56, 56, 56); /* the ground */
        glVertex3f(-70, 0, -70), glVertex3f(-70, 0, 70);
        glVertex3f(70, 0, 70), glVertex3f(70, 0, -70);
        glEnd();
        memset(at, 0, sizeof at);
        double x[2] = {0.0, 0.0}, t0 = 0.0; /* what the boxes send, and when they began */
        if (calib) {
            glFinish();
            t0 = glfwGetTime();
        }
        for (size_t i = 0; i < n; ++i) {
            draw_box(a.box[ids[i]], a.level[ids[i]]);
            ++at[a.level[ids[i]]];
            x[0] += 1.0, x[1] += level_vertices(a.level[ids[i]]);
        }
        if (calib) { /* the drawing's time to the model */
            glFinish();
            double ms = (glfwGetTime() - t0) * 1e3;
            tclod_calib_report_features(calib, x, ms, TCLOD_OFF);
            sum_ms += ms;
            sum_err += fabs(ms - target_ms) / target_ms;
        }
        if (shot && frame + 1 == frames && !write_ppm(shot, w, h)) {
            fprintf(stderr, "glfw_minimal: cannot write %s\n", shot);
            rc = 1;
        }
        glfwSwapBuffers(win);

        char title[128];
        snprintf(title, sizeof title, "glfw_minimal: budget %.2f ms, cost %.2f ms (+/-)",
                 a.budget_ms, stats.cost);
        glfwSetWindowTitle(win, title);
        ++frame;
    }
    if (frame) {
        printf("summary: frames=%lu budget_ms=%.3f mean_cost_ms=%.3f violations=%lu "
               "levels=%zu/%zu/%zu/%zu",
               frame, a.budget_ms, sum_cost / (double)frame, violations, at[0], at[1], at[2],
               at[3]);
        if (calib)
            printf(" target_ms=%.3f mean_ms=%.3f avg_err=%.4f", target_ms, sum_ms / (double)frame,
                   sum_err / (double)frame);
        printf("\n");
    }
    tclod_calib_destroy(calib);
    rc = violations ? 1 : rc;
    glfwDestroyWindow(win);
    glfwTerminate();
    tclod_selector_destroy(sel);
    tclod_scene_destroy(scene);
    return rc;
}
