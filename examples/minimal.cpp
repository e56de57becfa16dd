// minimal_cpp — the host of minimal.c in C++11 (docs/getting-started.md): the same
// field, flights and output, with the handles owned by std::unique_ptr, the host's
// data in std::vector and failures thrown as exceptions.
//
// The callbacks are called from C code: they must not throw.
#include <tclod/tclod.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

const int side = 8;            // statues per row: side x side on a 10 m grid
const int levels = 3;          // levels of detail per statue, coarsest first
const int frames = 15;         // frames of each flight
const double hz = 30.0;        // frames per second
const double speed = 40.0;     // the camera's speed, m/s
const double target_ms = 16.0; // the frame time the host aims at
const double slower = 1.5;     // measured render time per predicted ms (made up)
const double logic_ms = 2.0;   // measured logic time per frame (made up)

const double level_detail[levels] = {0.5, 0.8, 1.0};
const double level_ms[levels] = {0.05, 0.2, 0.6};

// Throws when a call fails, naming the call and the status.
#define CHECK(call) check((call), #call)

void check(tclod_status s, const char *call) {
    if (s != TCLOD_OK)
        throw std::runtime_error(std::string(call) + " failed: " + tclod_status_string(s));
}

// A handle that destroys its object when it goes out of scope.
template <class T, void (*destroy)(T *)> struct deleter {
    void operator()(T *p) const {
        destroy(p);
    }
};
// The scene goes last, after its selectors and schedulers (it refuses to go
// before them with TCLOD_ERR_STATE).
void destroy_scene(tclod_scene *s) {
    tclod_scene_destroy(s);
}
using scene_ptr = std::unique_ptr<tclod_scene, deleter<tclod_scene, destroy_scene>>;
using selector_ptr =
    std::unique_ptr<tclod_selector, deleter<tclod_selector, tclod_selector_destroy>>;
using calib_ptr = std::unique_ptr<tclod_calib, deleter<tclod_calib, tclod_calib_destroy>>;
using scheduler_ptr =
    std::unique_ptr<tclod_scheduler, deleter<tclod_scheduler, tclod_scheduler_destroy>>;

// The host's data, indexed by node id: a new scene numbers its nodes 0, 1, 2, ...
// in the order they are added.
struct world {
    explicit world(std::size_t nodes) : detail(nodes), ms(nodes), level(nodes) {
    }
    std::vector<double> detail; // how much of its statue a level shows
    std::vector<double> ms;     // predicted time to draw it
    std::vector<int> level;     // 0 = coarsest
};

// The camera at time t (s): 6 m up, flying into the field along z.
tclod_view camera_at(double t) {
    tclod_view v;
    std::memset(&v, 0, sizeof v);
    v.eye[0] = 35.0;
    v.eye[1] = 6.0;
    v.eye[2] = -30.0 + speed * t;
    v.forward[1] = -0.2f;
    v.forward[2] = 1.0f;
    v.up[1] = 1.0f;
    v.fov_y = 1.0f; // radians
    v.aspect = 16.0f / 9.0f;
    v.near_z = 0.1f;
    v.far_z = 1000.0f;
    v.viewport_height = 720.0f; // pixels
    return v;
}

// Prints how many of the nodes drawn are at each level, coarsest first.
void print_levels(const world &w, const tclod_id *ids, std::size_t n) {
    std::size_t at[levels] = {0, 0, 0};
    for (std::size_t i = 0; i < n; ++i)
        ++at[w.level[ids[i]]];
    std::printf("%5zu = %2zu + %2zu + %2zu", n, at[0], at[1], at[2]);
}

void run() {
    world w(side * side * levels);
    tclod_scene *s = nullptr;
    CHECK(tclod_scene_create(nullptr, &s));
    const scene_ptr scene(s);
    for (int i = 0; i < side * side; ++i) {
        const float bounds[4] = {10.0f * float(i % side), 1.0f, 10.0f * float(i / side), 1.5f};
        tclod_id node[levels]; // a statue of 3 levels is a chain
        for (int k = 0; k < levels; ++k) {
            CHECK(
                tclod_scene_add_node(scene.get(), k ? node[k - 1] : TCLOD_NONE, bounds, &node[k]));
            w.detail[node[k]] = level_detail[k];
            w.ms[node[k]] = level_ms[k];
            w.level[node[k]] = k;
        }
    }

    tclod_selector_desc desc;
    tclod_selector_desc_default(&desc);                             // greedy solver, warm start
    desc.callbacks.benefit = [](void *user, const tclod_query *q) { // 0 = not visible
        return q->screen_area > 0 ? static_cast<world *>(user)->detail[q->id] * q->screen_area
                                  : 0.0;
    };
    desc.callbacks.cost = [](void *user, const tclod_query *q) { // predicted ms
        return static_cast<world *>(user)->ms[q->id];
    };
    desc.callbacks.user = &w;
    desc.strict = 1; // a NaN or negative benefit or cost fails the call
    tclod_selector *sel_raw = nullptr;
    CHECK(tclod_selector_create(scene.get(), &desc, nullptr, &sel_raw));
    const selector_ptr sel(sel_raw);

    tclod_calib_desc calib_desc;
    tclod_calib_desc_default(&calib_desc);
    tclod_calib *calib_raw = nullptr;
    CHECK(tclod_calib_create(&calib_desc, nullptr, &calib_raw));
    const calib_ptr calib(calib_raw);

    std::printf("selector: frame, drawn = coarse + middle + fine, predicted ms <= budget\n");
    for (int frame = 0; frame < frames; ++frame) {
        const tclod_view camera = camera_at(frame / hz);
        double budget; // ms of predicted cost that fit target_ms on this machine
        CHECK(tclod_calib_budget(calib.get(), target_ms, &budget));
        tclod_frame fr;
        std::memset(&fr, 0, sizeof fr);
        fr.view = &camera;
        fr.budget = budget;
        tclod_stats stats;
        CHECK(tclod_select(sel.get(), &fr, &stats));
        const tclod_id *ids;
        std::size_t n;
        CHECK(tclod_selector_cut(sel.get(), &ids, &n));
        // draw(ids[0]) ... draw(ids[n - 1]), predicted to take stats.cost <= budget
        std::printf("%5d ", frame);
        print_levels(w, ids, n);
        std::printf("      %6.3f <= %6.3f\n", stats.cost, budget);
        CHECK(tclod_calib_report(calib.get(), stats.cost, slower * stats.cost, logic_ms));
    }

    tclod_scheduler_desc sched_desc;
    tclod_scheduler_desc_default(&sched_desc);
    sched_desc.tau = 0.1;                // s: each selection is for 0.2-0.3 s ahead
    sched_desc.max_speed = 1.25 * speed; // bounds the camera's predicted motion
    tclod_scheduler *sched_raw = nullptr;
    CHECK(tclod_scheduler_create(scene.get(), &desc, &sched_desc, nullptr, &sched_raw));
    const scheduler_ptr sched(sched_raw);

    std::vector<tclod_id> fine;
    std::printf("scheduler: frame, drawn = coarse + middle + fine (morphing), predicted ms <= "
                "budget\n");
    for (int frame = 0; frame < frames; ++frame) {
        const tclod_view camera = camera_at(frame / hz);
        double render_ms; // what rendering may take of target_ms
        CHECK(tclod_render_budget(target_ms, tclod_calib_logic(tclod_scheduler_calib(sched.get())),
                                  sched_desc.calib.machine_c, &render_ms));
        CHECK(tclod_scheduler_update(sched.get(), frame / hz, &camera, render_ms, 0.0005));
        const tclod_draw *items;
        std::size_t n;
        CHECK(tclod_scheduler_draws(sched.get(), &items, &n));
        tclod_scheduler_stats stats;
        CHECK(tclod_scheduler_get_stats(sched.get(), &stats));
        // draw(items[i].fine) geomorphed towards items[i].coarse by items[i].weight
        fine.clear();
        for (std::size_t i = 0; i < n; ++i)
            fine.push_back(items[i].fine);
        std::printf("%5d ", frame);
        print_levels(w, fine.data(), fine.size());
        std::printf(" (%2u) %6.3f <= %6.3f\n", unsigned(stats.morphing), stats.draw_cost,
                    stats.budget);
        CHECK(tclod_scheduler_report_frame(sched.get(), slower * stats.draw_cost, logic_ms));
    }
} // the handles are destroyed here, the scene last

const char usage[] =
    "usage: minimal_cpp [--help]\n"
    "\n"
    "The C++ twin of minimal: flies into a field of 64 statues of 3 levels of detail\n"
    "twice, selecting every frame within the budget the calibration gives for a 16 ms\n"
    "frame, then through the predictive scheduler. Prints a line per frame: the frame,\n"
    "the nodes drawn (as coarse + middle + fine), with the scheduler the ones morphing,\n"
    "and their predicted cost against the budget, in ms. Exit status 0, or 1 after\n"
    "naming the libtclod call that failed.\n";

} // namespace

int main(int argc, char **argv) {
    if (argc > 1) {
        const bool help = std::strcmp(argv[1], "--help") == 0;
        std::fputs(usage, help ? stdout : stderr);
        return help ? 0 : 2;
    }
    try {
        run();
        return 0;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "minimal_cpp: %s\n", e.what());
        return 1;
    }
}
