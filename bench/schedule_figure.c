/*
 * tclod_schedule_figure — data for docs/figures/schedule_timeline.svg: the
 * levels the predictive geomorph scheduler draws over time ([GEO Fig. 5]
 * and 6), from a real run over the flyover world (examples/scenes/
 * world_scene.h) at 60 frames per second, tau = 0.5 s, morphing on.
 *
 * Every frame the draw list gives each object of the world a level position:
 * its drawn level k, or k - 1 + w while level k morphs from level k - 1 with
 * weight w. After the run the program picks three objects that show the
 * schedule: the first whose level went up and later down, the one with the
 * largest jump within one interval, and the first other one whose level went
 * up. It checks that every level change of those objects started and ended
 * on interval boundaries, and exits with 1 when one did not.
 *
 * Output: CSV on stdout, columns kind, time_s, object, position:
 *   boundary  an interval boundary b_j (object and position empty)
 *   level     an object's level position at a frame (empty when not drawn)
 * Lines starting with '#' give tau, the frame rate and the objects picked.
 *
 *     ./build/bench/tclod_schedule_figure | python3 docs/figures/schedule_timeline.py \
 *         > docs/figures/schedule_timeline.svg
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <tclod/tclod.h>

#include "world_scene.h"

#define HZ 60.0
#define TAU 0.5
#define FRAMES 480u /* 8 s */
#define BUDGET_MS 10.0
/* The camera starts this far into its loop, where objects come and go. */
#define LOOP_START 0.1
#define FRAMES_PER_LOOP 2400.0
#define PICKED 3u

/* The level position of object o at frame f (NAN: not drawn). */
static float *positions;
static uint32_t object_count;

static float *at(uint32_t f, uint32_t o) {
    return &positions[(size_t)f * object_count + o];
}

/* Maps every object node to its object: object_of[node], or UINT32_MAX. */
static uint32_t *objects_of(const world_scene *w) {
    uint32_t *of = (uint32_t *)malloc(w->node_count * sizeof(uint32_t));
    uint32_t *root_obj = (uint32_t *)malloc(w->node_count * sizeof(uint32_t));
    uint32_t i, n;
    if (!of || !root_obj) {
        free(of);
        free(root_obj);
        return NULL;
    }
    for (n = 0; n < w->node_count; ++n)
        of[n] = root_obj[n] = UINT32_MAX;
    for (i = 0; i < w->object_count; ++i)
        root_obj[w->object_root[i]] = i;
    for (n = 0; n < w->node_count; ++n) {
        tclod_id a = n;
        if (w->kind[n] != WORLD_KIND_OBJECT)
            continue;
        while (w->level[a] > 0)
            a = tclod_scene_parent(w->scene, a);
        of[n] = root_obj[a];
    }
    free(root_obj);
    return of;
}

/* The object's position changes over the frames: ups, downs, the largest
 * change between two boundaries, and whether each change began and ended on
 * a boundary (within a frame). */
typedef struct history {
    uint32_t ups, downs;
    float largest;
    int aligned;
} history;

static history describe(uint32_t o) {
    const uint32_t per = (uint32_t)(TAU * HZ + 0.5);
    history h = {0, 0, 0.0f, 1};
    uint32_t f;
    for (f = 1; f < FRAMES; ++f) {
        float a = *at(f - 1, o), b = *at(f, o);
        if (isnan(a) || isnan(b) || a == b)
            continue;
        if (b > a)
            h.ups++;
        if (b < a)
            h.downs++;
    }
    for (f = 0; f + per < FRAMES; f += per) {
        float a = *at(f, o), b = *at(f + per, o);
        if (!isnan(a) && !isnan(b) && fabsf(b - a) > h.largest)
            h.largest = fabsf(b - a);
        /* a morph lasts a whole interval: a fractional position is never seen at
         * a boundary frame (the morph starts at weight 0 there) */
        if (!isnan(a) && a != floorf(a))
            h.aligned = 0;
    }
    return h;
}

static const char usage[] =
    "usage: tclod_schedule_figure [--help]\n"
    "\n"
    "Flies the flyover world for 8 s through the predictive geomorph scheduler (60 Hz,\n"
    "tau 0.5 s, morphing on) and writes the data of docs/figures/schedule_timeline.svg\n"
    "as CSV on stdout: '#' lines with tau, the frame rate and the three objects picked,\n"
    "then rows kind,time_s,object,position:\n"
    "  boundary  an interval boundary (object and position empty)\n"
    "  level     an object's level position at a frame: its level k, or k - 1 + w\n"
    "            while it morphs up with weight w (empty when not drawn)\n"
    "Exit status 1 when a level change of a picked object does not start and end on\n"
    "interval boundaries; 2 for a bad command line.\n";

int main(int argc, char **argv) {
    world_flyover_desc wd;
    world_scene w;
    tclod_selector_desc sd;
    tclod_scheduler_desc d;
    tclod_scheduler *sch = NULL;
    uint32_t *object_of = NULL, picked[PICKED], npicked = 0, f, o, k;
    int rc = 1;
    if (argc > 1) {
        int help = strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0;
        if (!help)
            fprintf(stderr, "tclod_schedule_figure: unknown argument '%s'\n", argv[1]);
        fputs(usage, help ? stdout : stderr);
        return help ? 0 : 2;
    }
    world_flyover_desc_default(&wd);
    if (world_build_flyover(&wd, &w) != TCLOD_OK) {
        fprintf(stderr, "tclod_schedule_figure: building the world failed\n");
        return 1;
    }
    object_count = w.object_count;
    positions = (float *)malloc((size_t)FRAMES * object_count * sizeof(float));
    object_of = objects_of(&w);
    tclod_selector_desc_default(&sd);
    sd.callbacks = world_callbacks(&w);
    tclod_scheduler_desc_default(&d);
    d.tau = TAU;
    d.max_speed = 300.0; /* above the loop's fastest, about 230 m/s */
    d.max_turn_rate = 1.0;
    if (!positions || !object_of ||
        tclod_scheduler_create(w.scene, &sd, &d, NULL, &sch) != TCLOD_OK) {
        fprintf(stderr, "tclod_schedule_figure: setting up failed\n");
        goto done;
    }
    for (f = 0; f < FRAMES; ++f) {
        tclod_view v;
        const tclod_draw *items;
        size_t n, i;
        world_camera_at(&w.path, LOOP_START + (double)f / FRAMES_PER_LOOP, &v);
        if (tclod_scheduler_update(sch, (double)f / HZ, &v, BUDGET_MS, 500e-6) != TCLOD_OK ||
            tclod_scheduler_draws(sch, &items, &n) != TCLOD_OK) {
            fprintf(stderr, "tclod_schedule_figure: the scheduler failed at frame %u\n", f);
            goto done;
        }
        for (o = 0; o < object_count; ++o)
            *at(f, o) = NAN;
        for (i = 0; i < n; ++i) {
            uint32_t obj = object_of[items[i].fine];
            if (obj == UINT32_MAX)
                continue;
            *at(f, obj) = items[i].fine == items[i].coarse
                              ? (float)w.level[items[i].fine]
                              : (float)w.level[items[i].coarse] + items[i].weight;
        }
    }
    /* the three objects of the figure */
    for (k = 0; k < PICKED; ++k) {
        uint32_t best = UINT32_MAX;
        float best_jump = 0.0f;
        for (o = 0; o < object_count; ++o) {
            history h = describe(o);
            uint32_t j;
            int taken = 0;
            for (j = 0; j < npicked; ++j)
                taken |= picked[j] == o;
            if (taken)
                continue;
            if (k == 0 && h.ups > 0 && h.downs > 0) {
                best = o;
                break;
            }
            if (k == 1 && h.largest > best_jump) {
                best = o;
                best_jump = h.largest;
            }
            if (k == 2 && h.ups > 0) {
                best = o;
                break;
            }
        }
        if (best != UINT32_MAX)
            picked[npicked++] = best;
    }
    printf("# tau %.3f s, %.0f frames per second, %u frames, budget %.1f ms\n", TAU, HZ, FRAMES,
           BUDGET_MS);
    printf("kind,time_s,object,position\n");
    for (f = 0; f * (1.0 / HZ) < FRAMES / HZ; f += (uint32_t)(TAU * HZ + 0.5))
        printf("boundary,%.6f,,\n", (double)f / HZ);
    rc = 0;
    for (k = 0; k < npicked; ++k) {
        history h = describe(picked[k]);
        printf("# object %u: %u frames going up, %u going down, largest change %.2f levels\n",
               picked[k], h.ups, h.downs, h.largest);
        if (!h.aligned) {
            fprintf(stderr, "tclod_schedule_figure: object %u morphs across a boundary\n",
                    picked[k]);
            rc = 1;
        }
        for (f = 0; f < FRAMES; ++f) {
            float p = *at(f, picked[k]);
            if (isnan(p))
                printf("level,%.6f,%u,\n", (double)f / HZ, picked[k]);
            else
                printf("level,%.6f,%u,%.4f\n", (double)f / HZ, picked[k], p);
        }
    }
    if (npicked < PICKED) {
        fprintf(stderr, "tclod_schedule_figure: found only %u objects that change\n", npicked);
        rc = 1;
    }
done:
    tclod_scheduler_destroy(sch);
    free(object_of);
    free(positions);
    world_scene_free(&w);
    return rc;
}
