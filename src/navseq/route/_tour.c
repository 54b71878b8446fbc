/*
 * navseq.route._tour — iterated local search over a route, in C (optional;
 * navseq/route/search.py has a pure-Python twin with the same moves, `_search_python`).
 *
 * search(costs, path, seconds, kicks, seed, settled) -> (list of nodes, settled)
 *
 *   costs   : C-contiguous int64 buffer, n x n arc costs (row: from, column: to);
 *             they may differ each way
 *   path    : int64 buffer, every node 0..n-1 once; its first and last node stay put
 *   seconds : stop once this much time passed (<= 0: no time limit)
 *   kicks   : stop after this many kicks (< 0: no limit)
 *   seed    : the kicks' random numbers (same seed and kicks: same answer)
 *   settled : the path is already locally optimal (a search's answer): no first descent
 *             over every node (on 2000 nodes it takes tens of milliseconds)
 *
 *   The answer's settled: its local search ran to the end (not cut by the time limit).
 *
 * The path is first made locally optimal for two moves, each priced with the arcs it
 * really drives: Or-opt (a run of 1 to 3 nodes moved elsewhere, either way round) and
 * 2-opt (a stretch driven backwards; prefix sums of both directions make each candidate
 * O(1)). Nodes to look at wait in a queue ("don't-look bits"): after a move only the
 * nodes at the changed arcs are looked at again. Then, until the limit: a kick (two
 * neighbouring stretches of the path swapped, a "segment double bridge", which keeps
 * every stretch's direction: it suits costs that differ each way), local search from
 * the nodes at the kick's arcs, and the result kept when it is no longer than the
 * current path (otherwise the current path is restored). The best path is returned,
 * never longer than the one given.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct {
    const int64_t *cost; /* n x n */
    Py_ssize_t n;
    int64_t *path;       /* position -> node */
    Py_ssize_t *pos;     /* node -> position */
    int64_t *fwd;        /* fwd[k]: cost of path[0..k] driven forwards */
    int64_t *bwd;        /* bwd[k]: the same arcs driven backwards */
    Py_ssize_t *queue;   /* nodes to look at (a ring) */
    char *queued;
    Py_ssize_t head, count;
    int64_t *scratch;
    double deadline;     /* 0: none */
} Search;

#define C(s, a, b) ((s)->cost[(a) * (s)->n + (b)])
#define LONGEST_RUN 3
#ifndef LONGEST_KICK
#define LONGEST_KICK 35
#endif

static void sums(Search *s) {
    s->fwd[0] = s->bwd[0] = 0;
    for (Py_ssize_t k = 1; k < s->n; k++) {
        s->fwd[k] = s->fwd[k - 1] + C(s, s->path[k - 1], s->path[k]);
        s->bwd[k] = s->bwd[k - 1] + C(s, s->path[k], s->path[k - 1]);
    }
    for (Py_ssize_t k = 0; k < s->n; k++) s->pos[s->path[k]] = k;
}

static void push(Search *s, int64_t node) {
    Py_ssize_t at = s->pos[node];
    if (at <= 0 || at >= s->n - 1 || s->queued[node]) return; /* the ends never move */
    s->queued[node] = 1;
    s->queue[(s->head + s->count) % s->n] = node;
    s->count++;
}

static void push_around(Search *s, Py_ssize_t at) {
    for (Py_ssize_t k = at - 1; k <= at + 1; k++)
        if (k >= 0 && k < s->n) push(s, s->path[k]);
}

/* Move path[a..b] (inclusive) to between path[g] and path[g + 1], reversed if asked. */
static void apply_move(Search *s, Py_ssize_t a, Py_ssize_t b, Py_ssize_t g, int reversed) {
    Py_ssize_t run = b - a + 1, w = 0;
    int64_t *out = s->scratch;
    for (Py_ssize_t k = 0; k < s->n; k++) {
        if (k >= a && k <= b) continue;
        out[w++] = s->path[k];
        if (k == g)
            for (Py_ssize_t j = 0; j < run; j++) out[w++] = s->path[reversed ? b - j : a + j];
    }
    memcpy(s->path, out, s->n * sizeof(int64_t));
}

static void reverse(Search *s, Py_ssize_t i, Py_ssize_t j) {
    for (; i < j; i++, j--) {
        int64_t t = s->path[i];
        s->path[i] = s->path[j];
        s->path[j] = t;
    }
}

/* The best move of node v's neighbourhood, applied if it saves anything: 1 if so. */
static int improve_node(Search *s, int64_t v) {
    Py_ssize_t n = s->n, p = s->pos[v];
    int64_t best = 0;
    int kind = 0, reversed = 0; /* 1: Or-opt, 2: 2-opt */
    Py_ssize_t ba = 0, bb = 0, bg = 0;
    /* Or-opt: runs that start or end at v. */
    for (Py_ssize_t run = 1; run <= LONGEST_RUN; run++) {
        for (int side = 0; side < (run == 1 ? 1 : 2); side++) {
            Py_ssize_t a = side ? p - run + 1 : p, b = a + run - 1;
            if (a < 1 || b > n - 2) continue;
            int64_t s0 = s->path[a], sk = s->path[b], prev = s->path[a - 1], next = s->path[b + 1];
            int64_t inner_f = s->fwd[b] - s->fwd[a], inner_b = s->bwd[b] - s->bwd[a];
            int64_t saved = C(s, prev, s0) + C(s, sk, next) - C(s, prev, next);
            for (Py_ssize_t g = 0; g < n - 1; g++) {
                if (g >= a - 1 && g <= b) continue;
                int64_t x = s->path[g], y = s->path[g + 1], base = C(s, x, y);
                int64_t d = C(s, x, s0) + C(s, sk, y) - base - saved;
                if (d < best) {
                    best = d, kind = 1, reversed = 0, ba = a, bb = b, bg = g;
                }
                if (run > 1) {
                    d = C(s, x, sk) + C(s, s0, y) - base - saved + inner_b - inner_f;
                    if (d < best) {
                        best = d, kind = 1, reversed = 1, ba = a, bb = b, bg = g;
                    }
                }
            }
        }
    }
    /* 2-opt: path[i..j] driven backwards, with v at one end of it. */
    for (Py_ssize_t other = 1; other < n - 1; other++) {
        if (other == p) continue;
        Py_ssize_t i = other < p ? other : p, j = other < p ? p : other;
        int64_t d = C(s, s->path[i - 1], s->path[j]) + C(s, s->path[i], s->path[j + 1]) -
                    C(s, s->path[i - 1], s->path[i]) - C(s, s->path[j], s->path[j + 1]) +
                    (s->bwd[j] - s->bwd[i]) - (s->fwd[j] - s->fwd[i]);
        if (d < best) {
            best = d, kind = 2, ba = i, bb = j;
        }
    }
    if (kind == 0) return 0;
    if (kind == 1) {
        Py_ssize_t at = bg < ba ? bg : bg - (bb - ba + 1);
        push_around(s, ba - 1 >= 0 ? ba - 1 : 0);
        push_around(s, bb + 1 < n ? bb + 1 : n - 1);
        apply_move(s, ba, bb, bg, reversed);
        sums(s);
        push_around(s, at);
        push_around(s, at + 1 + (bb - ba));
        push_around(s, at + (bb - ba) + 2 < n ? at + (bb - ba) + 2 : n - 1);
    } else {
        reverse(s, ba, bb);
        sums(s);
        push_around(s, ba);
        push_around(s, bb);
    }
    return 1;
}

static double now(void);

static void local_search(Search *s) {
    for (long long looked = 1; s->count > 0; looked++) {
        /* A long first descent (hundreds of places from a poor path) minds the limit. */
        if (s->deadline > 0 && (looked & 63) == 0 && now() >= s->deadline) return;
        int64_t v = s->queue[s->head];
        s->head = (s->head + 1) % s->n;
        s->count--;
        s->queued[v] = 0;
        if (improve_node(s, v)) push(s, v);
    }
}

static uint64_t next_random(uint64_t *state) {
    uint64_t x = *state;
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    return *state = x;
}

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

static PyObject *search(PyObject *self, PyObject *args) {
    Py_buffer cost_buf, path_buf;
    double seconds;
    long long kicks, seed;
    int settled = 0, best_settled = 1;
    if (!PyArg_ParseTuple(args, "y*y*dLL|p", &cost_buf, &path_buf, &seconds, &kicks, &seed,
                          &settled))
        return NULL;
    Py_ssize_t n = path_buf.len / (Py_ssize_t)sizeof(int64_t);
    PyObject *result = NULL;
    Search s = {0};
    int64_t *current = NULL;
    if (cost_buf.len != n * n * (Py_ssize_t)sizeof(int64_t)) {
        PyErr_SetString(PyExc_ValueError, "costs must be n x n int64 for a path of n nodes");
        goto done;
    }
    s.cost = cost_buf.buf;
    s.n = n;
    s.path = malloc(n * sizeof(int64_t));
    s.pos = malloc(n * sizeof(Py_ssize_t));
    s.fwd = malloc(n * sizeof(int64_t));
    s.bwd = malloc(n * sizeof(int64_t));
    s.queue = malloc(n * sizeof(Py_ssize_t));
    s.queued = calloc(n, 1);
    s.scratch = malloc(n * sizeof(int64_t));
    current = malloc(n * sizeof(int64_t));
    int64_t *best_path = malloc(n * sizeof(int64_t));
    if (!s.path || !s.pos || !s.fwd || !s.bwd || !s.queue || !s.queued || !s.scratch ||
        !current || !best_path) {
        free(best_path);
        PyErr_NoMemory();
        goto done;
    }
    memcpy(s.path, path_buf.buf, n * sizeof(int64_t));
    for (Py_ssize_t k = 0; k < n; k++) s.pos[k] = -1;
    for (Py_ssize_t k = 0; k < n; k++) {
        int64_t node = s.path[k];
        if (node < 0 || node >= n || s.pos[node] >= 0) {
            free(best_path);
            PyErr_SetString(PyExc_ValueError, "path must hold every node 0..n-1 once");
            goto done;
        }
        s.pos[node] = k;
    }
    if (n >= 4) {
        Py_BEGIN_ALLOW_THREADS;
        double began = now();
        s.deadline = seconds > 0 ? began + seconds : 0;
        uint64_t state = (uint64_t)seed * 2654435761u + 88172645463325252ull;
        sums(&s);
        if (!settled)
            for (Py_ssize_t k = 1; k < n - 1; k++) push(&s, s.path[k]);
        local_search(&s);
        best_settled = s.count == 0;
        int64_t length = s.fwd[n - 1], best = length;
        memcpy(current, s.path, n * sizeof(int64_t));
        memcpy(best_path, s.path, n * sizeof(int64_t));
        /* A kick swaps path[a..b-1] and path[b..c-1], inside positions 1..n-2. */
        for (long long kick = 0; n >= 5 && (kicks < 0 || kick < kicks); kick++) {
            if (seconds > 0 && now() - began >= seconds) break;
            Py_ssize_t inner = n - 2;
            Py_ssize_t a = 1 + (Py_ssize_t)(next_random(&state) % (uint64_t)(inner - 1));
            Py_ssize_t room = n - 1 - a; /* positions a..n-2 */
            Py_ssize_t most = room / 2 < LONGEST_KICK ? room / 2 : LONGEST_KICK;
            if (most < 1) continue;
            Py_ssize_t l1 = 1 + (Py_ssize_t)(next_random(&state) % (uint64_t)most);
            Py_ssize_t l2 = 1 + (Py_ssize_t)(next_random(&state) % (uint64_t)most);
            Py_ssize_t b = a + l1, c = b + l2;
            memcpy(s.scratch, s.path + b, l2 * sizeof(int64_t));
            memcpy(s.scratch + l2, s.path + a, l1 * sizeof(int64_t));
            memcpy(s.path + a, s.scratch, (l1 + l2) * sizeof(int64_t));
            sums(&s);
            push_around(&s, a);
            push_around(&s, a + l2);
            push_around(&s, c - 1);
            push_around(&s, c);
            local_search(&s);
            int64_t tried = s.fwd[n - 1];
            if (tried <= length) {
                length = tried;
                memcpy(current, s.path, n * sizeof(int64_t));
                if (tried < best) {
                    best = tried;
                    best_settled = s.count == 0;
                    memcpy(best_path, s.path, n * sizeof(int64_t));
                }
            } else {
                memcpy(s.path, current, n * sizeof(int64_t));
                sums(&s);
            }
        }
        memcpy(s.path, best_path, n * sizeof(int64_t));
        Py_END_ALLOW_THREADS;
    }
    free(best_path);
    PyObject *nodes = PyList_New(n);
    if (nodes == NULL) goto done;
    for (Py_ssize_t k = 0; k < n; k++) {
        PyObject *node = PyLong_FromLongLong(s.path[k]);
        if (node == NULL) {
            Py_DECREF(nodes);
            goto done;
        }
        PyList_SET_ITEM(nodes, k, node);
    }
    result = Py_BuildValue("(NO)", nodes, best_settled ? Py_True : Py_False);
done:
    free(s.path);
    free(s.pos);
    free(s.fwd);
    free(s.bwd);
    free(s.queue);
    free(s.queued);
    free(s.scratch);
    free(current);
    PyBuffer_Release(&cost_buf);
    PyBuffer_Release(&path_buf);
    return result;
}

static PyMethodDef methods[] = {
    {"search", search, METH_VARARGS,
     "search(costs, path, seconds, kicks, seed, settled) -> (list of nodes, settled)\n\n"
     "Iterated Or-opt and 2-opt over a path with fixed ends; see navseq.route.search."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_tour", "Compiled local search over a route for navseq's ordering.",
    -1, methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__tour(void) { return PyModule_Create(&module); }
