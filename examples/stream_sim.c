/*
 * stream_sim — the loader simulation of flyover_sim --stream and tclod_tiles
 * --stream. See stream_sim.h.
 */
#include "stream_sim.h"

#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A camera inside a node's volume is at distance 0: the error divides by
 * this instead, as CesiumJS does (CesiumMath.EPSILON7). */
#define MIN_DISTANCE 1e-7

/* ---- options --------------------------------------------------------------------- */

void stream_sim_options_default(stream_sim_options *o) {
    memset(o, 0, sizeof(*o));
    o->latency_ms = 50.0;
    o->bandwidth_mbps = 100.0;
    o->memory_mb = 0.0;
    o->teleport_every = 200;
}

const char stream_sim_usage_options[] =
    "  --stream        simulate streaming: every node but the roots starts not\n"
    "                  resident and a loader brings them in over a link, for\n"
    "                  libtclod's plan (tclod_selector_set_stream) and, on a second\n"
    "                  copy of the scene, for a baseline that requests by\n"
    "                  screen-space error (> 16 px) and evicts the least recently\n"
    "                  used; a third, all-resident copy gives the benefit the budget\n"
    "                  gives at best. 60 frames per simulated second, 20 loads in\n"
    "                  flight at most; frames default to 2000\n"
    "  --latency-ms L  --stream: a load's latency in ms, L >= 0 (default 50)\n"
    "  --bandwidth-mbps W\n"
    "                  --stream: the link's bandwidth in Mbit/s, W > 0 (default 100);\n"
    "                  loads share it one after the other\n"
    "  --memory-mb M   --stream: memory for resident nodes and loads in flight, in\n"
    "                  10^6 bytes, M > 0 (default: half of what the whole scene\n"
    "                  needs)\n"
    "  --teleport-every N\n"
    "                  --stream: every N frames the camera jumps to the one of 8\n"
    "                  points spread along its path (golden-ratio sequence) whose\n"
    "                  view needs the most bytes the view it leaves does not (by\n"
    "                  the baseline's traversal); N >= 0, 0 never (default 200)\n"
    "  --min-yield Y   --stream: the plan's tclod_stream_desc.min_yield, Y >= 0 or\n"
    "                  'off' (default 0: the library's default)\n";

const char stream_sim_usage_output[] =
    "--stream adds table columns (after the others):\n"
    "  resident_mb     MB resident when the frame was selected (ours)\n"
    "  requests        loads issued after the frame's select (ours)\n"
    "  in_flight       loads in flight after them (ours)\n"
    "  all_benefit     the benefit with every node resident\n"
    "  base_benefit    the baseline loader's benefit\n"
    "CSV columns (after the others):\n"
    "  resident_bytes  bytes resident when the frame was selected (ours)\n"
    "  requests        loads issued after the frame's select\n"
    "  in_flight       loads in flight after them\n"
    "  benefit_all_resident\n"
    "                  the benefit of the same budget and view with every node\n"
    "                  resident (the column benefit is ours)\n"
    "  resident_bytes_baseline, requests_baseline, in_flight_baseline,\n"
    "  benefit_baseline\n"
    "                  the same for the baseline loader\n"
    "and summary keys (after the others):\n"
    "  nonresident_draws      drawn nodes that the simulation's own residency\n"
    "                         says are not resident, both loaders (must be 0)\n"
    "  mem_violations         frames where resident bytes exceeded the memory\n"
    "                         budget, both loaders (must be 0)\n"
    "  t95_ms                 median over the start and each teleport of the\n"
    "                         simulated time, ms, until the selection's benefit\n"
    "                         reaches 95% of the all-resident benefit (not reached\n"
    "                         before the next teleport or the end: the time to it)\n"
    "  t95_baseline_ms        the same for the baseline\n"
    "  bytes_loaded           bytes of the loads completed\n"
    "  bytes_loaded_baseline  the same for the baseline\n"
    "  memory_bytes           the memory budget, bytes\n"
    "  needed_bytes_median, needed_bytes_max\n"
    "                         over the frames, the bytes of the nodes the\n"
    "                         all-resident selection draws and refines through:\n"
    "                         when above the memory, no loader can reach its\n"
    "                         benefit there\n";

/* A finite number and nothing else in s. */
static int parse_number(const char *s, double *out) {
    int used = -1;
    return sscanf(s, "%lf%n", out, &used) == 1 && used == (int)strlen(s) && isfinite(*out) &&
           !isspace((unsigned char)s[0]);
}

int stream_sim_parse_option(stream_sim_options *o, const char *prog, int argc, char **argv,
                            int *i) {
    const char *opt = argv[*i], *val = *i + 1 < argc ? argv[*i + 1] : NULL;
    double v = 0.0;
    if (strcmp(opt, "--stream") == 0) {
        o->enabled = 1;
        return 1;
    }
    if (strcmp(opt, "--latency-ms") != 0 && strcmp(opt, "--bandwidth-mbps") != 0 &&
        strcmp(opt, "--memory-mb") != 0 && strcmp(opt, "--teleport-every") != 0 &&
        strcmp(opt, "--min-yield") != 0)
        return 0;
    if (!val) {
        fprintf(stderr, "%s: option %s needs a value\n", prog, opt);
        return -1;
    }
    ++*i;
    o->given = 1;
    if (strcmp(opt, "--latency-ms") == 0) {
        if (!parse_number(val, &v) || !(v >= 0.0)) {
            fprintf(stderr, "%s: --latency-ms expects a number >= 0, got '%s'\n", prog, val);
            return -1;
        }
        o->latency_ms = v;
    } else if (strcmp(opt, "--bandwidth-mbps") == 0) {
        if (!parse_number(val, &v) || !(v > 0.0)) {
            fprintf(stderr, "%s: --bandwidth-mbps expects a number > 0, got '%s'\n", prog, val);
            return -1;
        }
        o->bandwidth_mbps = v;
    } else if (strcmp(opt, "--memory-mb") == 0) {
        if (!parse_number(val, &v) || !(v > 0.0) || v > 1e12) {
            fprintf(stderr, "%s: --memory-mb expects a number > 0, got '%s'\n", prog, val);
            return -1;
        }
        o->memory_mb = v;
    } else if (strcmp(opt, "--min-yield") == 0) {
        if (strcmp(val, "off") == 0) {
            o->min_yield = TCLOD_OFF;
        } else if (!parse_number(val, &v) || !(v >= 0.0) || v > 1e6) {
            fprintf(stderr, "%s: --min-yield expects a number >= 0 or 'off', got '%s'\n", prog,
                    val);
            return -1;
        } else {
            o->min_yield = v;
        }
    } else {
        if (!parse_number(val, &v) || !(v >= 0.0) || v != floor(v) || v > 1e8 || strchr(val, '.') ||
            strchr(val, 'e') || strchr(val, 'E')) {
            fprintf(stderr, "%s: --teleport-every expects an integer >= 0, got '%s'\n", prog, val);
            return -1;
        }
        o->teleport_every = (unsigned long)v;
    }
    return 1;
}

int stream_sim_options_check(const stream_sim_options *o, const char *prog) {
    if (o->given && !o->enabled) {
        fprintf(stderr,
                "%s: --latency-ms, --bandwidth-mbps, --memory-mb, --teleport-every and "
                "--min-yield need --stream\n",
                prog);
        return 0;
    }
    return 1;
}

/* ---- the path ---------------------------------------------------------------------- */

/* The j-th point of the golden-ratio sequence from STREAM_SIM_TELEPORT_SEED,
 * in [0, 1): spread evenly, the same on every platform. */
static double golden(unsigned long j) {
    return fmod(STREAM_SIM_TELEPORT_SEED + 0.6180339887498949 * (double)j, 1.0);
}

static double wrap(double position, double loop) {
    double p = fmod(position, loop);
    return p < 0.0 ? p + loop : p;
}

void stream_path_free(stream_path *p) {
    free(p->start);
    p->start = NULL;
}

double stream_path_position(const stream_path *p, unsigned long frame) {
    size_t k = p->every ? (size_t)(frame / p->every) : 0u;
    if (k >= p->events)
        k = p->events - 1;
    return wrap(p->start[k] + (double)(frame - (unsigned long)k * p->every), p->loop);
}

/* ---- the scene's structure ---------------------------------------------------------- */

/* Where a copy's sizes and errors come from: the host's arrays (the copies
 * alike) or its functions. */
typedef struct size_source {
    const double *bytes, *error;
    const stream_host *host; /* NULL: the arrays */
    int copy;
} size_source;

static void nodes_free(stream_nodes *n) {
    free(n->live);
    free(n->unexpanded);
    free(n->parent);
    free(n->first);
    free(n->child);
    free(n->roots);
    free(n->depth);
    free(n->bounds);
    free(n->bytes);
    free(n->error);
    memset(n, 0, sizeof(*n));
}

/* The structure of scene into *n (freed first). 0 when out of memory. */
static int nodes_read(stream_nodes *n, const tclod_scene *scene, const size_source *src) {
    uint32_t count = tclod_scene_node_count(scene), i;
    size_t room = count ? count : 1u;
    nodes_free(n);
    n->count = count;
    n->live = (uint8_t *)calloc(room, 1);
    n->unexpanded = (uint8_t *)calloc(room, 1);
    n->parent = (tclod_id *)malloc(room * sizeof(tclod_id));
    n->first = (uint32_t *)calloc(room + 1u, sizeof(uint32_t));
    n->child = (tclod_id *)malloc(room * sizeof(tclod_id));
    n->roots = (tclod_id *)malloc(room * sizeof(tclod_id));
    n->depth = (uint32_t *)calloc(room, sizeof(uint32_t));
    n->bounds = (tclod_bounds *)calloc(room, sizeof(tclod_bounds));
    n->bytes = (double *)calloc(room, sizeof(double));
    n->error = (double *)calloc(room, sizeof(double));
    if (!n->live || !n->unexpanded || !n->parent || !n->first || !n->child || !n->roots ||
        !n->depth || !n->bounds || !n->bytes || !n->error)
        return 0;
    for (i = 0; i < count; ++i) {
        n->parent[i] = TCLOD_NONE;
        if (!tclod_scene_node_live(scene, i))
            continue;
        n->live[i] = 1;
        n->parent[i] = tclod_scene_parent(scene, i);
        if (src->host) {
            void *u = src->host->user;
            n->bytes[i] = src->host->bytes(u, src->copy, i);
            n->error[i] = src->host->error(u, src->copy, i);
            n->unexpanded[i] = src->host->unexpanded && src->host->unexpanded(u, src->copy, i);
        } else {
            n->bytes[i] = src->bytes[i];
            n->error[i] = src->error[i];
        }
        if (n->unexpanded[i])
            n->unexpanded_count++;
        else
            n->total_bytes += n->bytes[i];
        if (tclod_scene_node_bounds(scene, i, &n->bounds[i]) != TCLOD_OK)
            n->bounds[i].kind = TCLOD_BOUNDS_NONE;
        if (n->parent[i] == TCLOD_NONE)
            n->roots[n->root_count++] = i;
        else
            n->first[n->parent[i] + 1u]++;
    }
    for (i = 0; i < count; ++i)
        n->first[i + 1u] += n->first[i];
    {
        /* children in id order: a counting sort by parent */
        uint32_t *fill = (uint32_t *)malloc(room * sizeof(uint32_t));
        if (!fill)
            return 0;
        memcpy(fill, n->first, room * sizeof(uint32_t));
        for (i = 0; i < count; ++i)
            if (n->live[i] && n->parent[i] != TCLOD_NONE)
                n->child[fill[n->parent[i]]++] = i;
        free(fill);
    }
    /* depths: the steps up to the root (ids are reused, so that a parent's
     * may be above its children's) */
    for (i = 0; i < count; ++i) {
        tclod_id a;
        if (!n->live[i])
            continue;
        for (a = n->parent[i]; a != TCLOD_NONE; a = n->parent[a])
            n->depth[i]++;
    }
    return 1;
}

/* ---- the loaders ---------------------------------------------------------------------- */

static int fail(const char *prog, const char *what, tclod_status st) {
    fprintf(stderr, "%s: %s failed: %s\n", prog, what, tclod_status_string(st));
    return 0;
}

static int out_of_memory(const char *prog) {
    fprintf(stderr, "%s: out of memory\n", prog);
    return 0;
}

static size_source source_of(const stream_sim *s, int copy) {
    size_source src;
    src.bytes = s->bytes;
    src.error = s->error;
    src.host = s->host.bytes ? &s->host : NULL;
    src.copy = copy;
    return src;
}

/* Grows the array *p of `size`-byte entries from `old` to `room` entries,
 * the new ones zero. 0 when out of memory (*p as it was). */
static int grow(void *p, size_t size, uint32_t old, uint32_t room) {
    void **q = (void **)p;
    char *g = (char *)realloc(*q, (size_t)room * size);
    if (!g)
        return 0;
    memset(g + (size_t)old * size, 0, (size_t)(room - old) * size);
    *q = g;
    return 1;
}

static int loader_grow(stream_sim *s, stream_loader *L, uint32_t count) {
    uint32_t room = L->room, old = L->room;
    if (count <= room && s->drawn_room >= count)
        return 1;
    while (room < count)
        room = room ? 2u * room : 64u;
    if (room > old &&
        !(grow(&L->state, 1, old, room) && grow(&L->used, sizeof(*L->used), old, room) &&
          grow(&L->kept, sizeof(*L->kept), old, room) &&
          grow(&L->stack, sizeof(*L->stack), old, room) &&
          grow(&L->walk, sizeof(*L->walk), old, room) &&
          grow(&L->walk_sse, sizeof(*L->walk_sse), old, room) &&
          grow(&L->wanted, sizeof(*L->wanted), old, room) &&
          grow(&L->lru, sizeof(*L->lru), old, room)))
        return 0;
    L->room = room;
    if (s->drawn_room < room) {
        if (!grow(&s->drawn, 1, s->drawn_room, room))
            return 0;
        s->drawn_room = room;
    }
    return 1;
}

/* Reads the loader's copy again: at the start, and after expansions. The
 * per-node arrays grow to the ids, and each node that is new since the last
 * read gets its size in the scene (the sim keeps what the scene gives back,
 * so that both count the same bytes) and its start: resident when it is a
 * root, has nothing to load or is of the all-resident copy; else absent
 * (marked so in the scene). Unexpanded nodes are absent. Ids of nodes gone
 * (expanded) are absent. 0 after a message. */
static int loader_refresh(stream_sim *s, stream_loader *L, const char *prog) {
    uint8_t *was = L->nodes.live;
    uint32_t was_count = L->nodes.count, i;
    size_source src = source_of(s, L->copy);
    stream_nodes *n = &L->nodes;
    tclod_status st = TCLOD_OK;
    L->nodes.live = NULL;
    if (!nodes_read(n, L->scene, &src) || !loader_grow(s, L, n->count)) {
        free(was);
        return out_of_memory(prog);
    }
    for (i = 0; i < was_count; ++i)
        if (was[i] && !n->live[i])
            L->state[i] = STREAM_ABSENT;
    for (i = 0; i < n->count && st == TCLOD_OK; ++i) {
        if (!n->live[i] || (i < was_count && was[i]))
            continue;
        L->state[i] = STREAM_ABSENT;
        if (n->unexpanded[i]) {
            n->bytes[i] = tclod_scene_node_bytes(L->scene, i);
            continue;
        }
        st = tclod_scene_set_node_bytes(L->scene, i, n->bytes[i]);
        if (st != TCLOD_OK) {
            fprintf(stderr, "%s: node %lu: its size %g bytes is refused: %s\n", prog,
                    (unsigned long)i, n->bytes[i], tclod_status_string(st));
            break;
        }
        n->total_bytes -= n->bytes[i];
        n->bytes[i] = tclod_scene_node_bytes(L->scene, i);
        n->total_bytes += n->bytes[i];
        if (L->copy != STREAM_SIM_ALL && n->parent[i] != TCLOD_NONE && n->bytes[i] > 0.0) {
            st = tclod_scene_set_resident(L->scene, i, 0);
            if (st != TCLOD_OK)
                fail(prog, "marking the scene's nodes absent", st);
        } else {
            L->state[i] = STREAM_RESIDENT;
            L->resident_bytes += n->bytes[i];
        }
    }
    free(was);
    L->grown = 0;
    return st == TCLOD_OK;
}

static void loader_free(stream_loader *L) {
    nodes_free(&L->nodes);
    free(L->state);
    free(L->t95_ms);
    free(L->used);
    free(L->kept);
    free(L->stack);
    free(L->wanted);
    free(L->lru);
    free(L->walk);
    free(L->walk_sse);
}

/* Issues the load of node id at time now (s). */
static void issue(stream_sim *s, stream_loader *L, tclod_id id, double now) {
    double bytes = L->nodes.bytes[id], begin = now + s->latency_s;
    stream_load *load = &L->loads[L->load_count++];
    if (L->link_free > begin)
        begin = L->link_free;
    L->link_free = begin + bytes / s->bytes_per_s;
    load->id = id;
    load->bytes = bytes;
    load->done = L->link_free;
    L->state[id] = STREAM_LOADING;
    L->flight_bytes += bytes;
    L->issued++;
}

/* The loads completed by now become resident, or for an unexpanded node
 * the host reads its file and puts what it holds in its place; then the
 * memory check. */
static int arrive(stream_sim *s, stream_loader *L, double now, const char *prog) {
    size_t k = 0, i;
    for (; k < L->load_count && L->loads[k].done <= now; ++k) {
        const stream_load *load = &L->loads[k];
        L->loaded_bytes += load->bytes;
        if (L->nodes.unexpanded[load->id]) {
            L->state[load->id] = STREAM_ABSENT;
            L->files++;
            L->grown = 1;
            if (!s->host.expand(s->host.user, L->copy, load->id))
                return 0;
            continue;
        }
        {
            tclod_status st = tclod_scene_set_resident(L->scene, load->id, 1);
            if (st != TCLOD_OK)
                return fail(prog, "tclod_scene_set_resident", st);
        }
        L->state[load->id] = STREAM_RESIDENT;
        L->resident_bytes += load->bytes;
    }
    memmove(L->loads, L->loads + k, (L->load_count - k) * sizeof(*L->loads));
    L->load_count -= k;
    if (L->grown && !loader_refresh(s, L, prog))
        return 0;
    /* summed again, so that no rounding builds up */
    L->flight_bytes = 0.0;
    for (i = 0; i < L->load_count; ++i)
        L->flight_bytes += L->loads[i].bytes;
    L->frame_resident_bytes = L->resident_bytes;
    L->issued = 0;
    if (L->resident_bytes > s->memory_bytes)
        L->mem_violations++;
    return 1;
}

static int evict(stream_loader *L, const stream_nodes *n, tclod_id id, const char *prog) {
    tclod_status st = tclod_scene_set_resident(L->scene, id, 0);
    if (st != TCLOD_OK)
        return fail(prog, "evicting a node (tclod_scene_set_resident)", st);
    L->state[id] = STREAM_ABSENT;
    L->resident_bytes -= n->bytes[id];
    return 1;
}

/* Counts the drawn nodes the loader's own residency says are absent. */
static void check_cut(stream_loader *L, const tclod_id *ids, size_t n) {
    size_t i;
    for (i = 0; i < n; ++i)
        if (L->state[ids[i]] != STREAM_RESIDENT)
            L->nonresident_draws++;
}

/* Ours: the plan's evictions, then its requests in the listed order, those in
 * flight skipped. */
static int ours_load(stream_sim *s, double now, const char *prog) {
    stream_loader *L = &s->ours;
    const tclod_stream_item *items;
    const tclod_id *cut;
    size_t drawn, n, i;
    tclod_status st = tclod_selector_cut(L->sel, &cut, &drawn);
    if (st != TCLOD_OK)
        return fail(prog, "tclod_selector_cut", st);
    check_cut(L, cut, drawn);
    for (i = 0; i < drawn; ++i)
        s->drawn[cut[i]] = 1;
    st = tclod_selector_evictions(L->sel, &items, &n);
    if (st != TCLOD_OK)
        return fail(prog, "tclod_selector_evictions", st);
    for (i = 0; i < n; ++i) {
        tclod_id id = items[i].id;
        if ((items[i].flags & TCLOD_STREAM_SMOOTH) || id >= L->nodes.count ||
            L->state[id] != STREAM_RESIDENT)
            continue;
        if (s->drawn[id])
            L->lost_drawn++;
        if (!evict(L, &L->nodes, id, prog))
            return 0;
    }
    for (i = 0; i < drawn; ++i)
        s->drawn[cut[i]] = 0;
    st = tclod_selector_requests(L->sel, &items, &n);
    if (st != TCLOD_OK)
        return fail(prog, "tclod_selector_requests", st);
    for (i = 0; i < n && L->load_count < STREAM_SIM_MAX_LOADS; ++i) {
        tclod_id id = items[i].id;
        if ((items[i].flags & TCLOD_STREAM_SMOOTH) || id >= L->nodes.count || !L->nodes.live[id] ||
            L->state[id] == STREAM_LOADING)
            continue;
        if (L->state[id] == STREAM_RESIDENT) {
            L->stale_requests++;
            continue;
        }
        issue(s, L, id, now);
    }
    return 1;
}

static int by_rank(const void *a, const void *b) {
    const stream_rank *x = (const stream_rank *)a, *y = (const stream_rank *)b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    if (x->depth != y->depth)
        return x->depth > y->depth ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id);
}

/* The screen-space error of node i from view v, px. */
static double node_sse(const stream_nodes *n, const tclod_view *v, tclod_id i) {
    double d = tclod_view_bounds_distance(v, &n->bounds[i]);
    if (!(d > MIN_DISTANCE))
        d = MIN_DISTANCE;
    return n->error[i] * (double)v->viewport_height / (2.0 * d * tan(0.5 * (double)v->fov_y));
}

/* The screen-space-error traversal: from the roots, visible nodes (the
 * frustum test) are wanted, and refined while their error exceeds
 * STREAM_SIM_MAX_SSE (a node with nothing to load always). The wanted nodes go
 * to out[] and their errors to sse[] (both room for every node); returns how
 * many. stack: room for every node. */
static size_t sse_walk(const stream_nodes *n, const tclod_view *v, tclod_id *stack, tclod_id *out,
                       double *sse) {
    size_t top = 0, wanted = 0;
    uint32_t r, k;
    for (r = n->root_count; r > 0; --r)
        stack[top++] = n->roots[r - 1u];
    while (top > 0) {
        tclod_id i = stack[--top];
        double e;
        if (!tclod_view_bounds_visible(v, &n->bounds[i]))
            continue;
        e = node_sse(n, v, i);
        out[wanted] = i;
        sse[wanted++] = e;
        if (n->bytes[i] > 0.0 && !(e > STREAM_SIM_MAX_SSE))
            continue;
        for (k = n->first[i + 1u]; k > n->first[i]; --k)
            stack[top++] = n->child[k - 1u];
    }
    return wanted;
}

/* The baseline's wanted nodes (sse_walk) marked used in this frame, and those
 * that are absent in L->wanted, the largest error first (then parents
 * first). Returns their number. */
static size_t sse_traversal(stream_loader *L, const tclod_view *v,
                            unsigned long stamp) {
    const stream_nodes *n = &L->nodes;
    size_t count = sse_walk(n, v, L->stack, L->walk, L->walk_sse), wanted = 0, k;
    for (k = 0; k < count; ++k) {
        tclod_id i = L->walk[k];
        L->used[i] = stamp;
        if (L->state[i] != STREAM_ABSENT)
            continue;
        L->wanted[wanted].key = -L->walk_sse[k];
        /* the order is the other way round for depth: parents first */
        L->wanted[wanted].depth = UINT32_MAX - n->depth[i];
        L->wanted[wanted].id = i;
        ++wanted;
    }
    qsort(L->wanted, wanted, sizeof(*L->wanted), by_rank);
    return wanted;
}

/* The baseline's eviction candidates, least recently used first: resident
 * nodes with bytes, no root, not drawn nor above a drawn node, not wanted in
 * this frame. */
static void lru_order(stream_loader *L, unsigned long stamp) {
    const stream_nodes *n = &L->nodes;
    uint32_t i;
    L->lru_count = L->lru_next = 0;
    L->lru_bytes = 0.0;
    for (i = 0; i < n->count; ++i) {
        if (L->state[i] != STREAM_RESIDENT || !(n->bytes[i] > 0.0) || n->parent[i] == TCLOD_NONE ||
            L->kept[i] == stamp || L->used[i] == stamp)
            continue;
        L->lru[L->lru_count].key = (double)L->used[i];
        L->lru[L->lru_count].depth = n->depth[i];
        L->lru[L->lru_count].id = i;
        L->lru_count++;
        L->lru_bytes += n->bytes[i];
    }
    qsort(L->lru, L->lru_count, sizeof(*L->lru), by_rank);
}

/* The baseline after its select: mark what is drawn, traverse, then request
 * the wanted nodes in order, evicting the least recently used first when
 * memory is short; it stops at the first request that cannot be made room
 * for. */
static int base_load(stream_sim *s, unsigned long frame, const tclod_view *v, double now,
                     const char *prog) {
    stream_loader *L = &s->base;
    const stream_nodes *n = &L->nodes;
    const tclod_id *ids;
    size_t count, i, wanted;
    unsigned long stamp = frame + 1u;
    int lru_ready = 0;
    tclod_status st = tclod_selector_cut(L->sel, &ids, &count);
    if (st != TCLOD_OK)
        return fail(prog, "tclod_selector_cut", st);
    check_cut(L, ids, count);
    for (i = 0; i < count; ++i) {
        tclod_id a;
        L->used[ids[i]] = stamp;
        for (a = ids[i]; a != TCLOD_NONE && L->kept[a] != stamp; a = n->parent[a])
            L->kept[a] = stamp;
    }
    wanted = sse_traversal(L, v, stamp);
    for (i = 0; i < wanted && L->load_count < STREAM_SIM_MAX_LOADS; ++i) {
        tclod_id id = L->wanted[i].id;
        double short_by = L->resident_bytes + L->flight_bytes + n->bytes[id] - s->memory_bytes;
        if (short_by > 0.0) {
            if (!lru_ready) {
                lru_order(L, stamp);
                lru_ready = 1;
            }
            if (L->lru_bytes < short_by)
                break;
            while (short_by > 0.0) {
                tclod_id victim = L->lru[L->lru_next++].id;
                L->lru_bytes -= n->bytes[victim];
                short_by -= n->bytes[victim];
                if (!evict(L, n, victim, prog))
                    return 0;
            }
        }
        issue(s, L, id, now);
    }
    return 1;
}

/* ---- the teleports ------------------------------------------------------------------ */

/* The bytes the traversal wants at view v that it did not want where mark[]
 * holds stamp. */
static double new_bytes(const stream_nodes *n, const tclod_view *v, tclod_id *stack, tclod_id *out,
                        double *sse, const uint32_t *mark, uint32_t stamp) {
    size_t count = sse_walk(n, v, stack, out, sse), k;
    double bytes = 0.0;
    for (k = 0; k < count; ++k)
        if (mark[out[k]] != stamp)
            bytes += n->bytes[out[k]];
    return bytes;
}

/* How far position b lies from a along a closed path of length loop. */
static double along(double a, double b, double loop) {
    double d = fabs(a - b);
    return d < loop - d ? d : loop - d;
}

int stream_path_init(stream_path *p, double loop, unsigned long every, unsigned long frames,
                     stream_sim_view_fn view, void *user, const tclod_scene *scene,
                     const double *bytes, const double *error, const stream_host *host) {
    size_source src;
    unsigned long draws = 0;
    stream_nodes n;
    size_t k, room;
    tclod_id *stack = NULL, *out = NULL;
    double *sse = NULL;
    uint32_t *mark = NULL;
    int ok;
    memset(p, 0, sizeof(*p));
    memset(&n, 0, sizeof(n));
    p->loop = loop;
    p->every = every;
    p->events = every ? (size_t)((frames + every - 1) / every) : 1u;
    if (p->events < 1)
        p->events = 1;
    p->start = (double *)malloc(p->events * sizeof(*p->start));
    src.bytes = bytes;
    src.error = error;
    src.host = host;
    src.copy = STREAM_SIM_OURS;
    ok = p->start && nodes_read(&n, scene, &src);
    room = n.count ? n.count : 1u;
    if (ok) {
        stack = (tclod_id *)malloc(room * sizeof(tclod_id));
        out = (tclod_id *)malloc(room * sizeof(tclod_id));
        sse = (double *)malloc(room * sizeof(double));
        mark = (uint32_t *)calloc(room, sizeof(uint32_t));
        ok = stack && out && sse && mark;
    }
    if (ok)
        p->start[0] = 0.0;
    for (k = 1; ok && k < p->events; ++k) {
        tclod_view here;
        double best = -1.0, leave = wrap(p->start[k - 1] + (double)every, loop);
        size_t count, i;
        unsigned c;
        view(user, leave, &here);
        count = sse_walk(&n, &here, stack, out, sse);
        for (i = 0; i < count; ++i)
            mark[out[i]] = (uint32_t)k;
        for (c = 0; c < STREAM_SIM_TELEPORT_CANDIDATES; ++c) {
            double at = floor(golden(draws++) * loop), b;
            tclod_view there;
            view(user, at, &there);
            b = new_bytes(&n, &there, stack, out, sse, mark, (uint32_t)k);
            if (b > best ||
                (b == best && along(leave, at, loop) > along(leave, p->start[k], loop))) {
                best = b;
                p->start[k] = at;
            }
        }
    }
    nodes_free(&n);
    free(stack);
    free(out);
    free(sse);
    free(mark);
    return ok;
}

/* ---- the simulation --------------------------------------------------------------------- */

int stream_sim_start(stream_sim *s, const stream_sim_options *opt, unsigned long frames,
                     tclod_scene *ours, tclod_selector *ours_sel, tclod_scene *base,
                     tclod_scene *all, const tclod_selector_desc *sd, const double *bytes,
                     const double *error, const stream_host *host, const char *prog) {
    tclod_selector_desc copy_sd[2];
    tclod_status st = TCLOD_OK;
    int k;
    memset(s, 0, sizeof(*s));
    s->opt = *opt;
    s->frames = frames;
    s->latency_s = opt->latency_ms * 1e-3;
    s->bytes_per_s = opt->bandwidth_mbps * 1e6 / 8.0;
    s->bytes = bytes;
    s->error = error;
    if (host)
        s->host = *host;
    s->events = opt->teleport_every
                    ? (size_t)((frames + opt->teleport_every - 1u) / opt->teleport_every)
                    : 1u;
    s->needed = (double *)calloc(frames ? frames : 1u, sizeof(double));
    s->ours.t95_ms = (double *)calloc(s->events, sizeof(double));
    s->base.t95_ms = (double *)calloc(s->events, sizeof(double));
    if (!s->needed || !s->ours.t95_ms || !s->base.t95_ms)
        return out_of_memory(prog);
    for (k = 0; k < 2 && st == TCLOD_OK; ++k) {
        copy_sd[k] = *sd;
        if (s->host.selector_user[k])
            copy_sd[k].callbacks.user = s->host.selector_user[k];
        st = tclod_selector_create(k ? all : base, &copy_sd[k], NULL, k ? &s->all.sel : &s->base.sel);
    }
    if (st != TCLOD_OK)
        return fail(prog, "creating the baseline's and the all-resident selectors", st);
    s->ours.copy = STREAM_SIM_OURS;
    s->ours.scene = ours;
    s->ours.sel = ours_sel;
    s->base.copy = STREAM_SIM_BASE;
    s->base.scene = base;
    s->all.copy = STREAM_SIM_ALL;
    s->all.scene = all;
    if (!loader_refresh(s, &s->ours, prog) || !loader_refresh(s, &s->base, prog) ||
        !loader_refresh(s, &s->all, prog))
        return 0;
    s->scene_bytes = s->host.scene_bytes > 0.0 ? s->host.scene_bytes : s->ours.nodes.total_bytes;
    s->memory_bytes = opt->memory_mb > 0.0 ? opt->memory_mb * 1e6 : 0.5 * s->scene_bytes;
    if (s->host.expand && s->all.nodes.unexpanded_count) {
        /* the all-resident copy expands what its plan asks for, at once */
        tclod_stream_desc d;
        memset(&d, 0, sizeof(d));
        d.max_requests = STREAM_SIM_EXPAND_BATCH;
        d.min_yield = TCLOD_OFF;
        st = tclod_selector_set_stream(s->all.sel, &d);
        if (st != TCLOD_OK)
            return fail(prog, "tclod_selector_set_stream (all resident)", st);
    }
    return 1;
}

void stream_sim_free(stream_sim *s) {
    tclod_selector_destroy(s->base.sel);
    tclod_selector_destroy(s->all.sel);
    loader_free(&s->ours);
    loader_free(&s->base);
    loader_free(&s->all);
    free(s->drawn);
    free(s->needed);
    memset(s, 0, sizeof(*s));
}

int stream_sim_before(stream_sim *s, unsigned long frame, const char *prog) {
    double now = (double)frame / STREAM_SIM_HZ;
    tclod_stream_desc d;
    tclod_status st;
    if (!arrive(s, &s->ours, now, prog) || !arrive(s, &s->base, now, prog))
        return 0;
    /* the plan may list loads in flight again (it knows their bytes only):
     * room for as many requests as loads may be in flight */
    memset(&d, 0, sizeof(d));
    d.max_requests = STREAM_SIM_MAX_LOADS;
    d.memory_budget = s->memory_bytes;
    d.bytes_in_flight = s->ours.flight_bytes;
    d.min_yield = s->opt.min_yield;
    st = tclod_selector_set_stream(s->ours.sel, &d);
    if (st != TCLOD_OK)
        return fail(prog, "tclod_selector_set_stream", st);
    return 1;
}

/* The event (start or teleport) frame falls in; at a new one the times of
 * the last are closed. */
static void follow_t95(stream_sim *s, unsigned long frame) {
    stream_loader *loaders[2];
    size_t event = s->opt.teleport_every ? (size_t)(frame / s->opt.teleport_every) : 0u;
    double since_ms = (double)(frame - s->event_frame) * 1000.0 / STREAM_SIM_HZ;
    int i;
    loaders[0] = &s->ours;
    loaders[1] = &s->base;
    if (frame == 0 || event != s->event) {
        for (i = 0; i < 2 && frame > 0; ++i)
            if (!loaders[i]->reached)
                loaders[i]->t95_ms[s->event] = since_ms;
        s->event = event < s->events ? event : s->events - 1u;
        s->event_frame = frame;
        since_ms = 0.0;
        loaders[0]->reached = loaders[1]->reached = 0;
    }
    for (i = 0; i < 2; ++i) {
        if (!loaders[i]->reached && loaders[i]->benefit >= STREAM_SIM_T95_SHARE * s->all_benefit) {
            loaders[i]->t95_ms[s->event] = since_ms;
            loaders[i]->reached = 1;
        }
    }
}

/* The bytes of the nodes the all-resident selection draws and of their
 * ancestors, each once, into *out. 0 after a message. */
static int needed_bytes(stream_sim *s, double *out, const char *prog) {
    const stream_nodes *N = &s->all.nodes;
    const tclod_id *cut;
    size_t n, i;
    double sum = 0.0;
    tclod_id a;
    tclod_status st = tclod_selector_cut(s->all.sel, &cut, &n);
    if (st != TCLOD_OK)
        return fail(prog, "the all-resident tclod_selector_cut", st);
    for (i = 0; i < n; ++i)
        for (a = cut[i]; a != TCLOD_NONE && a < N->count && !s->drawn[a]; a = N->parent[a]) {
            s->drawn[a] = 1;
            sum += N->bytes[a];
        }
    for (i = 0; i < n; ++i)
        for (a = cut[i]; a != TCLOD_NONE && a < N->count && s->drawn[a]; a = N->parent[a])
            s->drawn[a] = 0;
    *out = sum;
    return 1;
}

/* The all-resident copy's select; while its plan asks to expand nodes (a
 * host reading on demand), they are expanded and it selects again, at most
 * STREAM_SIM_EXPAND_ROUNDS times. 0 after a message. */
static int all_select(stream_sim *s, const tclod_frame *fr, tclod_stats *stats,
                      const char *prog) {
    stream_loader *L = &s->all;
    unsigned round;
    for (round = 0;; ++round) {
        const tclod_stream_item *items;
        size_t n, i, expand = 0;
        tclod_status st = tclod_select(L->sel, fr, stats);
        if (st != TCLOD_OK)
            return fail(prog, "the all-resident tclod_select", st);
        if (!s->host.expand || !L->nodes.unexpanded_count || round == STREAM_SIM_EXPAND_ROUNDS)
            return 1;
        st = tclod_selector_requests(L->sel, &items, &n);
        if (st != TCLOD_OK)
            return fail(prog, "the all-resident tclod_selector_requests", st);
        for (i = 0; i < n; ++i) {
            tclod_id id = items[i].id;
            if ((items[i].flags & TCLOD_STREAM_EXPAND) && id < L->nodes.count &&
                L->nodes.live[id] && L->nodes.unexpanded[id])
                L->walk[expand++] = id;
        }
        if (expand == 0)
            return 1;
        for (i = 0; i < expand; ++i) {
            L->files++;
            if (!s->host.expand(s->host.user, STREAM_SIM_ALL, L->walk[i]))
                return 0;
        }
        if (!loader_refresh(s, L, prog))
            return 0;
    }
}

int stream_sim_after(stream_sim *s, unsigned long frame, const tclod_frame *fr, double benefit,
                     const char *prog) {
    double now = (double)frame / STREAM_SIM_HZ;
    tclod_stats stats;
    tclod_status st;
    s->ours.benefit = benefit;
    if (!ours_load(s, now, prog))
        return 0;
    st = tclod_select(s->base.sel, fr, &stats);
    if (st != TCLOD_OK)
        return fail(prog, "the baseline's tclod_select", st);
    s->base.benefit = stats.benefit;
    if (!base_load(s, frame, fr->view, now, prog))
        return 0;
    if (!all_select(s, fr, &stats, prog))
        return 0;
    s->all_benefit = stats.benefit;
    if (frame < s->frames && !needed_bytes(s, &s->needed[frame], prog))
        return 0;
    follow_t95(s, frame);
    return 1;
}

void stream_sim_table_header(FILE *out) {
    fprintf(out, " %11s %8s %9s %12s %12s", "resident_mb", "requests", "in_flight", "all_benefit",
            "base_benefit");
}

void stream_sim_table_row(FILE *out, const stream_sim *s) {
    fprintf(out, " %11.1f %8lu %9lu %12.1f %12.1f", s->ours.frame_resident_bytes * 1e-6,
            s->ours.issued, (unsigned long)s->ours.load_count, s->all_benefit, s->base.benefit);
}

void stream_sim_csv_header(FILE *out) {
    fputs(",resident_bytes,requests,in_flight,benefit_all_resident,resident_bytes_baseline,"
          "requests_baseline,in_flight_baseline,benefit_baseline",
          out);
}

void stream_sim_csv_row(FILE *out, const stream_sim *s) {
    fprintf(out, ",%.0f,%lu,%lu,%.9g,%.0f,%lu,%lu,%.9g", s->ours.frame_resident_bytes,
            s->ours.issued, (unsigned long)s->ours.load_count, s->all_benefit,
            s->base.frame_resident_bytes, s->base.issued, (unsigned long)s->base.load_count,
            s->base.benefit);
}

static int compare_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The median of the per-event times; sorts them. */
static double median_t95(stream_loader *L, size_t events) {
    qsort(L->t95_ms, events, sizeof(double), compare_double);
    return events % 2 ? L->t95_ms[events / 2]
                      : 0.5 * (L->t95_ms[events / 2 - 1] + L->t95_ms[events / 2]);
}

void stream_sim_print_summary(FILE *out, stream_sim *s) {
    double end_ms = (double)(s->frames - s->event_frame) * 1000.0 / STREAM_SIM_HZ;
    size_t events = s->event + 1u;
    if (!s->ours.reached)
        s->ours.t95_ms[s->event] = end_ms;
    if (!s->base.reached)
        s->base.t95_ms[s->event] = end_ms;
    if (s->ours.stale_requests || s->ours.lost_drawn)
        fprintf(stderr,
                "stream: the plan requested %lu resident nodes and evicted %lu drawn nodes\n",
                s->ours.stale_requests, s->ours.lost_drawn);
    fprintf(out,
            " nonresident_draws=%lu mem_violations=%lu t95_ms=%.1f t95_baseline_ms=%.1f "
            "bytes_loaded=%.0f bytes_loaded_baseline=%.0f",
            s->ours.nonresident_draws + s->base.nonresident_draws,
            s->ours.mem_violations + s->base.mem_violations, median_t95(&s->ours, events),
            median_t95(&s->base, events), s->ours.loaded_bytes, s->base.loaded_bytes);
    {
        double max = 0.0;
        unsigned long i;
        for (i = 0; i < s->frames; ++i)
            max = s->needed[i] > max ? s->needed[i] : max;
        qsort(s->needed, s->frames, sizeof(double), compare_double);
        fprintf(out, " memory_bytes=%.0f needed_bytes_median=%.0f needed_bytes_max=%.0f",
                s->memory_bytes,
                s->frames % 2 ? s->needed[s->frames / 2]
                              : 0.5 * (s->needed[s->frames / 2 - 1] + s->needed[s->frames / 2]),
                max);
    }
    fprintf(out, " files_read=%lu files_read_baseline=%lu files_read_all_resident=%lu",
            s->ours.files, s->base.files, s->all.files);
}

void stream_sim_print_settings(FILE *out, const stream_sim *s) {
    char needs[64];
    if (s->ours.nodes.unexpanded_count && !(s->host.scene_bytes > 0.0))
        snprintf(needs, sizeof(needs), "not known before it is read");
    else
        snprintf(needs, sizeof(needs), "%.1f MB", s->scene_bytes * 1e-6);
    fprintf(out,
            "stream: latency %g ms, bandwidth %g Mbit/s, memory %.1f MB (the scene needs "
            "%s), %u loads in flight at most, %g frames per s, teleport every %lu "
            "frames; baseline: refine above %g px, evict the least recently used\n",
            s->opt.latency_ms, s->opt.bandwidth_mbps, s->memory_bytes * 1e-6,
            needs, STREAM_SIM_MAX_LOADS, STREAM_SIM_HZ, s->opt.teleport_every,
            STREAM_SIM_MAX_SSE);
    if (s->ours.nodes.unexpanded_count)
        fprintf(out,
                "stream: the hierarchy is read on demand: each copy starts with %lu nodes, "
                "%lu of them unexpanded (files not read)\n",
                (unsigned long)(s->ours.nodes.count), (unsigned long)s->ours.nodes.unexpanded_count);
}
