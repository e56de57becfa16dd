/*
 * minimal — a complete libtclod host in C99 (docs/getting-started.md).
 *
 * 64 statues of three levels of detail stand on a field; a camera flies into it.
 * Every frame the host turns its target frame time into a budget (the calibration),
 * selects the levels that fit it (the selector), "draws" them and reports how long
 * drawing took. Then it flies the same path through the predictive scheduler, which
 * selects ahead and changes levels by geomorphs. Nothing is drawn: the measured
 * render time is made up as SLOWER times the predicted cost (a machine slower than
 * the host's cost model says), and the logic time as LOGIC_MS.
 *
 * Every call that can fail is checked; the program exits 0, or 1 after naming the
 * call that failed and why.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <tclod/tclod.h>

#define SIDE 8         /* statues per row: SIDE x SIDE on a 10 m grid */
#define LEVELS 3       /* levels of detail per statue, coarsest first */
#define FRAMES 15      /* frames of each flight */
#define HZ 30.0        /* frames per second */
#define SPEED 40.0     /* the camera's speed, m/s */
#define TARGET_MS 16.0 /* the frame time the host aims at */
#define SLOWER 1.5     /* measured render time per predicted ms (made up) */
#define LOGIC_MS 2.0   /* measured logic time per frame (made up) */

/* Stops the program when a call fails, naming the call and the status. */
#define CHECK(call) check((call), #call)

static void check(tclod_status s, const char *call) {
    if (s != TCLOD_OK) {
        fprintf(stderr, "minimal: %s failed: %s\n", call, tclod_status_string(s));
        exit(1);
    }
}

/* The host's data, in arrays indexed by node id: a new scene numbers its nodes
 * 0, 1, 2, ... in the order they are added. */
struct world {
    double detail[SIDE * SIDE * LEVELS]; /* how much of its statue a level shows */
    double ms[SIDE * SIDE * LEVELS];     /* predicted time to draw it */
    int level[SIDE * SIDE * LEVELS];     /* 0 = coarsest */
};

static const double level_detail[LEVELS] = {0.5, 0.8, 1.0};
static const double level_ms[LEVELS] = {0.05, 0.2, 0.6};

static double benefit(void *user, const tclod_query *q) { /* 0 = not visible */
    return q->screen_area > 0 ? ((struct world *)user)->detail[q->id] * q->screen_area : 0.0;
}
static double cost(void *user, const tclod_query *q) { /* predicted ms */
    return ((struct world *)user)->ms[q->id];
}

/* The camera at time t (s): 6 m up, flying into the field along z. */
static tclod_view camera_at(double t) {
    return (tclod_view){.eye = {35.0, 6.0, -30.0 + SPEED * t},
                        .forward = {0.0f, -0.2f, 1.0f},
                        .up = {0.0f, 1.0f, 0.0f},
                        .fov_y = 1.0f, /* radians */
                        .aspect = 16.0f / 9.0f,
                        .near_z = 0.1f,
                        .far_z = 1000.0f,
                        .viewport_height = 720.0f /* pixels */};
}

/* Prints how many of the n nodes drawn are at each level, coarsest first. */
static void print_levels(const struct world *world, const tclod_id *ids, size_t n) {
    size_t at[LEVELS] = {0};
    for (size_t i = 0; i < n; ++i)
        ++at[world->level[ids[i]]];
    printf("%5zu = %2zu + %2zu + %2zu", n, at[0], at[1], at[2]);
}

static const char usage[] =
    "usage: minimal [--help]\n"
    "\n"
    "Flies into a field of 64 statues of 3 levels of detail twice: selecting every\n"
    "frame within the budget the calibration gives for a 16 ms frame, then through\n"
    "the predictive scheduler. Prints a line per frame: the frame, the nodes drawn\n"
    "(as coarse + middle + fine), with the scheduler the ones morphing, and their\n"
    "predicted cost against the budget, in ms. Exit status 0, or 1 after naming the\n"
    "libtclod call that failed.\n";

int main(int argc, char **argv) {
    if (argc > 1) {
        int help = strcmp(argv[1], "--help") == 0;
        fputs(usage, help ? stdout : stderr);
        return help ? 0 : 2;
    }

    struct world world;
    tclod_scene *scene;
    CHECK(tclod_scene_create(NULL, &scene));
    for (int i = 0; i < SIDE * SIDE; ++i) {
        const float bounds[4] = {10.0f * (float)(i % SIDE), 1.0f, 10.0f * (float)(i / SIDE), 1.5f};
        tclod_id node[LEVELS]; /* a statue of 3 levels is a chain; a terrain patch has 4 children */
        for (int k = 0; k < LEVELS; ++k) {
            CHECK(tclod_scene_add_node(scene, k ? node[k - 1] : TCLOD_NONE, bounds, &node[k]));
            world.detail[node[k]] = level_detail[k];
            world.ms[node[k]] = level_ms[k];
            world.level[node[k]] = k;
        }
    }

    tclod_selector_desc desc;
    tclod_selector_desc_default(&desc); /* greedy solver, warm start */
    desc.callbacks = (tclod_callbacks){.benefit = benefit, .cost = cost, .user = &world};
    desc.strict = 1; /* a NaN or negative benefit or cost fails the call */
    tclod_selector *sel;
    CHECK(tclod_selector_create(scene, &desc, NULL, &sel));

    tclod_calib_desc calib_desc;
    tclod_calib_desc_default(&calib_desc);
    tclod_calib *calib;
    CHECK(tclod_calib_create(&calib_desc, NULL, &calib));

    printf("selector: frame, drawn = coarse + middle + fine, predicted ms <= budget\n");
    for (int frame = 0; frame < FRAMES; ++frame) { /* every frame */
        const tclod_view camera = camera_at(frame / HZ);
        double budget; /* ms of predicted cost that fit TARGET_MS on this machine */
        CHECK(tclod_calib_budget(calib, TARGET_MS, &budget));
        tclod_stats stats;
        CHECK(tclod_select(sel, &(tclod_frame){.view = &camera, .budget = budget}, &stats));
        const tclod_id *ids;
        size_t n;
        CHECK(tclod_selector_cut(sel, &ids, &n));
        /* draw(ids[0]) ... draw(ids[n - 1]), predicted to take stats.cost <= budget */
        printf("%5d ", frame);
        print_levels(&world, ids, n);
        printf("      %6.3f <= %6.3f\n", stats.cost, budget);
        CHECK(tclod_calib_report(calib, stats.cost, SLOWER * stats.cost, LOGIC_MS));
    }

    tclod_scheduler_desc sched_desc;
    tclod_scheduler_desc_default(&sched_desc);
    sched_desc.tau = 0.1;                /* s: each selection is for 0.2-0.3 s ahead */
    sched_desc.max_speed = 1.25 * SPEED; /* bounds the camera's predicted motion */
    tclod_scheduler *sched;
    CHECK(tclod_scheduler_create(scene, &desc, &sched_desc, NULL, &sched));

    printf("scheduler: frame, drawn = coarse + middle + fine (morphing), predicted ms <= "
           "budget\n");
    for (int frame = 0; frame < FRAMES; ++frame) {
        const tclod_view camera = camera_at(frame / HZ);
        double render_ms; /* what rendering may take of TARGET_MS */
        CHECK(tclod_render_budget(TARGET_MS, tclod_calib_logic(tclod_scheduler_calib(sched)),
                                  sched_desc.calib.machine_c, &render_ms));
        CHECK(tclod_scheduler_update(sched, frame / HZ, &camera, render_ms, 0.0005));
        const tclod_draw *items;
        size_t n;
        CHECK(tclod_scheduler_draws(sched, &items, &n));
        tclod_scheduler_stats stats;
        CHECK(tclod_scheduler_get_stats(sched, &stats));
        /* draw(items[i].fine) geomorphed towards items[i].coarse by items[i].weight */
        tclod_id fine[SIDE * SIDE * LEVELS];
        for (size_t i = 0; i < n; ++i)
            fine[i] = items[i].fine;
        printf("%5d ", frame);
        print_levels(&world, fine, n);
        printf(" (%2u) %6.3f <= %6.3f\n", (unsigned)stats.morphing, stats.draw_cost, stats.budget);
        CHECK(tclod_scheduler_report_frame(sched, SLOWER * stats.draw_cost, LOGIC_MS));
    }

    tclod_scheduler_destroy(sched);
    tclod_calib_destroy(calib);
    tclod_selector_destroy(sel);
    tclod_scene_destroy(scene);
    return 0;
}
