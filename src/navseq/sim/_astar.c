/*
 * navseq.sim._astar — the planner's A* search in C (optional; planner.py has a
 * pure-Python twin with the same semantics, `_search_python`).
 *
 * search(cost, width, lut, start, goal, heuristic_scale) -> (total, [cells]) | None
 *
 *   cost   : C-contiguous uint8 buffer, height x width costmap bytes (row-major)
 *   lut    : 256 float64 traversal costs, one per cost byte; inf = impassable
 *   start, goal : flat cell indices (row * width + col)
 *   heuristic_scale : a lower bound on every finite traversal cost
 *
 * distances(cost, width, lut, start, targets) -> bytes (float64 per target)
 * routes(cost, width, lut, start, targets, anchor_cells) -> bytes (3 float64 per target)
 * local(cost, width, lut, start, bound, queries, anchor_cells) -> bytes (3 float64 per query)
 * graph(indptr, indices, edge_cost, edge_length, seeds, seed_cost, seed_length, wanted)
 *
 *   local and graph serve the coarse distances of navseq.route.coarse: an exact search
 *   near a place, and a search over the coarse graph of a map's free space.
 *
 *   targets : int64 flat cell indices; the result is each one's length in cells along
 *             the cheapest route from start (inf when there is none), from one search
 *
 * A step between 8-neighbours a -> b costs |step| * (lut[a] + lut[b]) / 2, |step|
 * being 1 or sqrt(2). The heuristic is the octile distance times heuristic_scale,
 * which is admissible and consistent, so the goal's first pop is optimal. Queue
 * entries are never decreased in place: a better route pushes a new entry and the
 * stale one is skipped when popped (cells are closed once). The GIL is released
 * during the search.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

typedef struct {
    double f;     /* g + heuristic */
    double g;     /* cost from the start */
    int64_t cell;
} Entry;

typedef struct {
    Entry *items;
    size_t size;
    size_t capacity;
} Heap;

/* Smaller f first; on ties the deeper entry (larger g), which expands fewer cells. */
static inline int before(const Entry *a, const Entry *b) {
    return a->f < b->f || (a->f == b->f && a->g > b->g);
}

static int heap_push(Heap *heap, Entry entry) {
    if (heap->size == heap->capacity) {
        size_t capacity = heap->capacity ? 2 * heap->capacity : 1024;
        Entry *items = realloc(heap->items, capacity * sizeof(Entry));
        if (items == NULL) return -1;
        heap->items = items;
        heap->capacity = capacity;
    }
    size_t i = heap->size++;
    while (i > 0) {
        size_t parent = (i - 1) / 2;
        if (!before(&entry, &heap->items[parent])) break;
        heap->items[i] = heap->items[parent];
        i = parent;
    }
    heap->items[i] = entry;
    return 0;
}

static Entry heap_pop(Heap *heap) {
    Entry top = heap->items[0];
    Entry last = heap->items[--heap->size];
    size_t n = heap->size, i = 0;
    if (n == 0) return top;
    for (;;) {
        size_t child = 2 * i + 1;
        if (child >= n) break;
        if (child + 1 < n && before(&heap->items[child + 1], &heap->items[child])) child++;
        if (!before(&heap->items[child], &last)) break;
        heap->items[i] = heap->items[child];
        i = child;
    }
    heap->items[i] = last;
    return top;
}

typedef enum { FOUND, NO_PATH, OUT_OF_MEMORY } Outcome;

static Outcome astar(const uint8_t *cost, int64_t height, int64_t width, const double *lut,
                     int64_t start, int64_t goal, double heuristic_scale, int32_t *parent,
                     double *best, uint8_t *closed, double *total) {
    static const int d_row[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
    static const int d_col[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
    const double diagonal = sqrt(2.0), diagonal_extra = sqrt(2.0) - 1.0;
    const int64_t goal_row = goal / width, goal_col = goal % width;
    /* closed[]: 0 unseen (best[] not yet written: a short plan on a big map touches
     * only the cells it expands, not every cell), 1 queued, 2 closed. */
    Heap heap = {NULL, 0, 0};
    Outcome outcome = NO_PATH;
    best[start] = 0.0;
    closed[start] = 1;
    parent[start] = (int32_t)start;
    {
        int64_t dr = llabs(start / width - goal_row), dc = llabs(start % width - goal_col);
        double h = heuristic_scale * (fmax(dr, dc) + diagonal_extra * fmin(dr, dc));
        if (heap_push(&heap, (Entry){h, 0.0, start}) < 0) return OUT_OF_MEMORY;
    }
    while (heap.size > 0) {
        Entry entry = heap_pop(&heap);
        int64_t cell = entry.cell;
        if (closed[cell] == 2) continue;
        closed[cell] = 2;
        if (cell == goal) {
            *total = entry.g;
            outcome = FOUND;
            break;
        }
        int64_t row = cell / width, col = cell % width;
        double here = lut[cost[cell]];
        for (int k = 0; k < 8; k++) {
            int64_t r = row + d_row[k], c = col + d_col[k];
            if (r < 0 || r >= height || c < 0 || c >= width) continue;
            int64_t next = r * width + c;
            if (closed[next] == 2) continue;
            double there = lut[cost[next]];
            if (isinf(there)) continue;
            double step = (d_row[k] != 0 && d_col[k] != 0) ? diagonal : 1.0;
            double g = entry.g + step * 0.5 * (here + there);
            if (closed[next] == 0 || g < best[next]) {
                closed[next] = 1;
                best[next] = g;
                parent[next] = (int32_t)cell;
                int64_t dr = llabs(r - goal_row), dc = llabs(c - goal_col);
                double h = heuristic_scale * (fmax(dr, dc) + diagonal_extra * fmin(dr, dc));
                if (heap_push(&heap, (Entry){g + h, g, next}) < 0) {
                    outcome = OUT_OF_MEMORY;
                    break;
                }
            }
        }
        if (outcome == OUT_OF_MEMORY) break;
    }
    free(heap.items);
    return outcome;
}

static PyObject *search(PyObject *self, PyObject *args) {
    Py_buffer cost_buffer, lut_buffer;
    Py_ssize_t width, start, goal;
    double heuristic_scale;
    (void)self;
    if (!PyArg_ParseTuple(args, "y*ny*nnd", &cost_buffer, &width, &lut_buffer, &start, &goal,
                          &heuristic_scale))
        return NULL;

    PyObject *result = NULL;
    int32_t *parent = NULL;
    double *best = NULL;
    uint8_t *closed = NULL;
    Py_ssize_t n = cost_buffer.len;
    if (width <= 0 || n % width != 0) {
        PyErr_SetString(PyExc_ValueError, "cost buffer size is not a multiple of width");
        goto done;
    }
    if (n > INT32_MAX) {
        PyErr_SetString(PyExc_ValueError, "grids above 2**31 cells are not supported");
        goto done;
    }
    if (lut_buffer.len != 256 * (Py_ssize_t)sizeof(double)) {
        PyErr_SetString(PyExc_ValueError, "lut must hold 256 float64 values");
        goto done;
    }
    if (start < 0 || start >= n || goal < 0 || goal >= n) {
        PyErr_SetString(PyExc_IndexError, "start or goal cell outside the grid");
        goto done;
    }
    const uint8_t *cost = cost_buffer.buf;
    const double *lut = lut_buffer.buf;
    if (isinf(lut[cost[start]]) || isinf(lut[cost[goal]])) {
        result = Py_NewRef(Py_None);
        goto done;
    }
    parent = malloc((size_t)n * sizeof(int32_t));
    best = malloc((size_t)n * sizeof(double));
    closed = calloc((size_t)n, 1);
    if (parent == NULL || best == NULL || closed == NULL) {
        PyErr_NoMemory();
        goto done;
    }

    Outcome outcome;
    double total = 0.0;
    Py_BEGIN_ALLOW_THREADS
    outcome = astar(cost, n / width, width, lut, start, goal, heuristic_scale, parent, best,
                    closed, &total);
    Py_END_ALLOW_THREADS

    if (outcome == OUT_OF_MEMORY) {
        PyErr_NoMemory();
        goto done;
    }
    if (outcome == NO_PATH) {
        result = Py_NewRef(Py_None);
        goto done;
    }
    Py_ssize_t length = 1;
    for (int64_t cell = goal; cell != start; cell = parent[cell]) length++;
    PyObject *cells = PyList_New(length);
    if (cells == NULL) goto done;
    int64_t cell = goal;
    for (Py_ssize_t i = length - 1; i >= 0; i--) {
        PyObject *index = PyLong_FromLongLong(cell);
        if (index == NULL) {
            Py_DECREF(cells);
            goto done;
        }
        PyList_SET_ITEM(cells, i, index);
        cell = parent[cell];
    }
    result = Py_BuildValue("(dN)", total, cells);

done:
    free(parent);
    free(best);
    free(closed);
    PyBuffer_Release(&cost_buffer);
    PyBuffer_Release(&lut_buffer);
    return result;
}

/* Dijkstra from `start` until every wanted cell is closed: the length (in cells, along
 * the cheapest route's steps) to each wanted cell, INFINITY for one it cannot reach. The
 * cheapest route is the one A* finds (same step costs); its geometric length is kept
 * beside its cost as the search goes. */
static Outcome reach(const uint8_t *cost, int64_t height, int64_t width, const double *lut,
                     int64_t start, uint8_t *wanted, int64_t remaining, double *best,
                     double *length, uint8_t *closed, int32_t *parent, int32_t *anchor,
                     double anchor_cells) {
    static const int d_row[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
    static const int d_col[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
    const double diagonal = sqrt(2.0);
    int64_t n = height * width;
    for (int64_t i = 0; i < n; i++) best[i] = length[i] = INFINITY;
    Heap heap = {NULL, 0, 0};
    best[start] = length[start] = 0.0;
    if (parent != NULL) parent[start] = anchor[start] = (int32_t)start;
    if (heap_push(&heap, (Entry){0.0, 0.0, start}) < 0) return OUT_OF_MEMORY;
    while (heap.size > 0 && remaining > 0) {
        Entry entry = heap_pop(&heap);
        int64_t cell = entry.cell;
        if (closed[cell]) continue;
        closed[cell] = 1;
        if (wanted[cell]) {
            wanted[cell] = 0;
            remaining--;
        }
        int64_t row = cell / width, col = cell % width;
        double here = lut[cost[cell]];
        for (int k = 0; k < 8; k++) {
            int64_t r = row + d_row[k], c = col + d_col[k];
            if (r < 0 || r >= height || c < 0 || c >= width) continue;
            int64_t next = r * width + c;
            if (closed[next]) continue;
            double there = lut[cost[next]];
            if (isinf(there)) continue;
            double step = (d_row[k] != 0 && d_col[k] != 0) ? diagonal : 1.0;
            double g = entry.g + step * 0.5 * (here + there);
            if (g < best[next]) {
                best[next] = g;
                length[next] = length[cell] + step;
                if (parent != NULL) {
                    /* The departure anchor: the last cell of the route within
                     * anchor_cells of the start (the cell itself while it is that near). */
                    parent[next] = (int32_t)cell;
                    anchor[next] = length[next] <= anchor_cells ? (int32_t)next : anchor[cell];
                }
                if (heap_push(&heap, (Entry){g, g, next}) < 0) {
                    free(heap.items);
                    return OUT_OF_MEMORY;
                }
            }
        }
    }
    free(heap.items);
    return FOUND;
}

/* What a search from `start` to `cells` (int64 flat indices) over a cost grid of `n`
 * cells `width` wide is given, checked alike by every multi-target search: 0 when it
 * holds, else -1 with the Python error set (`plural` / `singular` name the cells:
 * "targets" / "target"). */
static int check_search(Py_ssize_t n, Py_ssize_t width, const Py_buffer *lut, Py_ssize_t start,
                        const Py_buffer *cells, const char *plural, const char *singular) {
    if (width <= 0 || n % width != 0) {
        PyErr_SetString(PyExc_ValueError, "cost buffer size is not a multiple of width");
        return -1;
    }
    if (n > INT32_MAX) {
        PyErr_SetString(PyExc_ValueError, "grids above 2**31 cells are not supported");
        return -1;
    }
    if (lut->len != 256 * (Py_ssize_t)sizeof(double) ||
        cells->len % (Py_ssize_t)sizeof(int64_t) != 0) {
        PyErr_Format(PyExc_ValueError, "lut must hold 256 float64, %s int64 values", plural);
        return -1;
    }
    if (start < 0 || start >= n) {
        PyErr_SetString(PyExc_IndexError, "start cell outside the grid");
        return -1;
    }
    const int64_t *cell = cells->buf;
    for (Py_ssize_t i = 0; i < cells->len / (Py_ssize_t)sizeof(int64_t); i++) {
        if (cell[i] < 0 || cell[i] >= n) {
            PyErr_Format(PyExc_IndexError, "%s cell outside the grid", singular);
            return -1;
        }
    }
    return 0;
}

static PyObject *distances(PyObject *self, PyObject *args) {
    Py_buffer cost_buffer, lut_buffer, target_buffer;
    Py_ssize_t width, start;
    (void)self;
    if (!PyArg_ParseTuple(args, "y*ny*ny*", &cost_buffer, &width, &lut_buffer, &start,
                          &target_buffer))
        return NULL;
    PyObject *result = NULL;
    double *best = NULL, *length = NULL;
    uint8_t *closed = NULL, *wanted = NULL;
    Py_ssize_t n = cost_buffer.len;
    Py_ssize_t count = target_buffer.len / (Py_ssize_t)sizeof(int64_t);
    const int64_t *targets = target_buffer.buf;
    if (check_search(n, width, &lut_buffer, start, &target_buffer, "targets", "target") < 0)
        goto finish;
    best = malloc((size_t)n * sizeof(double));
    length = malloc((size_t)n * sizeof(double));
    closed = calloc((size_t)n, 1);
    wanted = calloc((size_t)n, 1);
    result = PyBytes_FromStringAndSize(NULL, count * (Py_ssize_t)sizeof(double));
    if (best == NULL || length == NULL || closed == NULL || wanted == NULL || result == NULL) {
        Py_CLEAR(result);
        PyErr_NoMemory();
        goto finish;
    }
    const uint8_t *cost = cost_buffer.buf;
    const double *lut = lut_buffer.buf;
    double *out = (double *)PyBytes_AS_STRING(result);
    Outcome outcome = FOUND;
    Py_BEGIN_ALLOW_THREADS
    int64_t remaining = 0;
    for (Py_ssize_t i = 0; i < count; i++) {
        if (!wanted[targets[i]] && !isinf(lut[cost[targets[i]]])) {
            wanted[targets[i]] = 1;
            remaining++;
        }
    }
    if (!isinf(lut[cost[start]])) {
        outcome = reach(cost, n / width, width, lut, start, wanted, remaining, best, length,
                        closed, NULL, NULL, 0.0);
    } else {
        for (int64_t i = 0; i < n; i++) length[i] = INFINITY;
    }
    for (Py_ssize_t i = 0; i < count; i++) out[i] = length[targets[i]];
    Py_END_ALLOW_THREADS
    if (outcome == OUT_OF_MEMORY) {
        Py_CLEAR(result);
        PyErr_NoMemory();
    }

finish:
    free(best);
    free(length);
    free(closed);
    free(wanted);
    PyBuffer_Release(&cost_buffer);
    PyBuffer_Release(&lut_buffer);
    PyBuffer_Release(&target_buffer);
    return result;
}

/* routes(): as distances(), plus where each route leaves and arrives: per target three
 * float64 — the length in cells, the departure anchor (the route's last cell within
 * anchor_cells of the start) and the arrival anchor (the route's first cell within
 * anchor_cells of the target), as flat cell indices; -1 for both anchors when there is
 * no route. The headings a robot leaves and arrives with are the directions start ->
 * departure anchor and arrival anchor -> target. */
static PyObject *routes(PyObject *self, PyObject *args) {
    Py_buffer cost_buffer, lut_buffer, target_buffer;
    Py_ssize_t width, start;
    double anchor_cells;
    (void)self;
    if (!PyArg_ParseTuple(args, "y*ny*ny*d", &cost_buffer, &width, &lut_buffer, &start,
                          &target_buffer, &anchor_cells))
        return NULL;
    PyObject *result = NULL;
    double *best = NULL, *length = NULL;
    uint8_t *closed = NULL, *wanted = NULL;
    int32_t *parent = NULL, *anchor = NULL;
    Py_ssize_t n = cost_buffer.len;
    Py_ssize_t count = target_buffer.len / (Py_ssize_t)sizeof(int64_t);
    const int64_t *targets = target_buffer.buf;
    if (check_search(n, width, &lut_buffer, start, &target_buffer, "targets", "target") < 0)
        goto finish;
    best = malloc((size_t)n * sizeof(double));
    length = malloc((size_t)n * sizeof(double));
    parent = malloc((size_t)n * sizeof(int32_t));
    anchor = malloc((size_t)n * sizeof(int32_t));
    closed = calloc((size_t)n, 1);
    wanted = calloc((size_t)n, 1);
    result = PyBytes_FromStringAndSize(NULL, 3 * count * (Py_ssize_t)sizeof(double));
    if (best == NULL || length == NULL || parent == NULL || anchor == NULL || closed == NULL ||
        wanted == NULL || result == NULL) {
        Py_CLEAR(result);
        PyErr_NoMemory();
        goto finish;
    }
    const uint8_t *cost = cost_buffer.buf;
    const double *lut = lut_buffer.buf;
    double *out = (double *)PyBytes_AS_STRING(result);
    Outcome outcome = FOUND;
    Py_BEGIN_ALLOW_THREADS
    int64_t remaining = 0;
    for (Py_ssize_t i = 0; i < count; i++) {
        if (!wanted[targets[i]] && !isinf(lut[cost[targets[i]]])) {
            wanted[targets[i]] = 1;
            remaining++;
        }
    }
    if (!isinf(lut[cost[start]])) {
        outcome = reach(cost, n / width, width, lut, start, wanted, remaining, best, length,
                        closed, parent, anchor, anchor_cells);
    } else {
        for (int64_t i = 0; i < n; i++) length[i] = INFINITY;
    }
    for (Py_ssize_t i = 0; i < count; i++) {
        int64_t target = targets[i];
        double total = length[target];
        out[3 * i] = total;
        if (isinf(total) || !closed[target]) {
            out[3 * i] = INFINITY;
            out[3 * i + 1] = out[3 * i + 2] = -1.0;
            continue;
        }
        int64_t back = target;
        while (back != start && total - length[back] < anchor_cells) back = parent[back];
        out[3 * i + 1] = (double)anchor[target];
        out[3 * i + 2] = (double)back;
    }
    Py_END_ALLOW_THREADS
    if (outcome == OUT_OF_MEMORY) {
        Py_CLEAR(result);
        PyErr_NoMemory();
    }

finish:
    free(best);
    free(length);
    free(parent);
    free(anchor);
    free(closed);
    free(wanted);
    PyBuffer_Release(&cost_buffer);
    PyBuffer_Release(&lut_buffer);
    PyBuffer_Release(&target_buffer);
    return result;
}

/* local(cost, width, lut, start, bound, queries, anchor_cells) -> bytes (3 float64 per
 * query): Dijkstra from `start` over the cells whose cost from it is at most `bound`
 * (every one of them exactly, as a whole search would), then per query cell its length
 * in cells along the cheapest route, that route's cost, and its departure anchor (the
 * route's last cell within anchor_cells of the start) as a flat index; inf, inf, -1 for
 * a query the bound did not reach. Memory is taken lazily (calloc'd state, untouched
 * pages never written), so a small search on a big map costs what it expands. */
static PyObject *local(PyObject *self, PyObject *args) {
    Py_buffer cost_buffer, lut_buffer, query_buffer;
    Py_ssize_t width, start;
    double bound, anchor_cells;
    (void)self;
    if (!PyArg_ParseTuple(args, "y*ny*ndy*d", &cost_buffer, &width, &lut_buffer, &start, &bound,
                          &query_buffer, &anchor_cells))
        return NULL;
    PyObject *result = NULL;
    double *best = NULL, *length = NULL;
    int32_t *anchor = NULL;
    uint8_t *state = NULL; /* 0 unseen, 1 queued, 2 closed */
    Heap heap = {NULL, 0, 0};
    Py_ssize_t n = cost_buffer.len;
    Py_ssize_t count = query_buffer.len / (Py_ssize_t)sizeof(int64_t);
    const int64_t *queries = query_buffer.buf;
    if (check_search(n, width, &lut_buffer, start, &query_buffer, "queries", "query") < 0)
        goto finish;
    best = malloc((size_t)n * sizeof(double));
    length = malloc((size_t)n * sizeof(double));
    anchor = malloc((size_t)n * sizeof(int32_t));
    state = calloc((size_t)n, 1);
    result = PyBytes_FromStringAndSize(NULL, 3 * count * (Py_ssize_t)sizeof(double));
    if (best == NULL || length == NULL || anchor == NULL || state == NULL || result == NULL) {
        Py_CLEAR(result);
        PyErr_NoMemory();
        goto finish;
    }
    const uint8_t *cost = cost_buffer.buf;
    const double *lut = lut_buffer.buf;
    double *out = (double *)PyBytes_AS_STRING(result);
    int failed = 0;
    Py_BEGIN_ALLOW_THREADS
    static const int d_row[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
    static const int d_col[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
    const double diagonal = sqrt(2.0);
    const int64_t height = n / width;
    if (!isinf(lut[cost[start]])) {
        best[start] = length[start] = 0.0;
        anchor[start] = (int32_t)start;
        state[start] = 1;
        failed = heap_push(&heap, (Entry){0.0, 0.0, start}) < 0;
    }
    while (!failed && heap.size > 0) {
        Entry entry = heap_pop(&heap);
        int64_t cell = entry.cell;
        if (state[cell] == 2 || entry.g > best[cell]) continue;
        if (entry.g > bound) break;
        state[cell] = 2;
        int64_t row = cell / width, col = cell % width;
        double here = lut[cost[cell]];
        for (int k = 0; k < 8; k++) {
            int64_t r = row + d_row[k], c = col + d_col[k];
            if (r < 0 || r >= height || c < 0 || c >= width) continue;
            int64_t next = r * width + c;
            if (state[next] == 2) continue;
            double there = lut[cost[next]];
            if (isinf(there)) continue;
            double step = (d_row[k] != 0 && d_col[k] != 0) ? diagonal : 1.0;
            double g = entry.g + step * 0.5 * (here + there);
            if (state[next] == 0 || g < best[next]) {
                state[next] = 1;
                best[next] = g;
                length[next] = length[cell] + step;
                anchor[next] = length[next] <= anchor_cells ? (int32_t)next : anchor[cell];
                if (heap_push(&heap, (Entry){g, g, next}) < 0) {
                    failed = 1;
                    break;
                }
            }
        }
    }
    for (Py_ssize_t i = 0; i < count; i++) {
        int64_t query = queries[i];
        if (state[query] == 2) {
            out[3 * i] = length[query];
            out[3 * i + 1] = best[query];
            out[3 * i + 2] = (double)anchor[query];
        } else {
            out[3 * i] = out[3 * i + 1] = INFINITY;
            out[3 * i + 2] = -1.0;
        }
    }
    Py_END_ALLOW_THREADS
    if (failed) {
        Py_CLEAR(result);
        PyErr_NoMemory();
    }

finish:
    free(heap.items);
    free(best);
    free(length);
    free(anchor);
    free(state);
    PyBuffer_Release(&cost_buffer);
    PyBuffer_Release(&lut_buffer);
    PyBuffer_Release(&query_buffer);
    return result;
}

/* The buckets of Dinitz's Dijkstra: bucket k holds the nodes whose cost may be in
 * [k * width, (k + 1) * width), width at most the cheapest edge. A node popped from the
 * lowest bucket is then final whatever its place in the bucket (an edge from another
 * node of the bucket adds at least a width), so no heap is needed: pushes and pops cost
 * a constant, where the heap's log of a hundred thousand entries missed the cache at
 * every level (the coarse graph's searches took twice as long). Costs never span more
 * than the dearest edge (or the seeds' spread) past the lowest bucket, so `count`
 * buckets are used round and round. */
typedef struct {
    int64_t *items;
    size_t size;
    size_t capacity;
} Bucket;

static int bucket_push(Bucket *bucket, int64_t node) {
    if (bucket->size == bucket->capacity) {
        size_t capacity = bucket->capacity ? 2 * bucket->capacity : 64;
        int64_t *items = realloc(bucket->items, capacity * sizeof(int64_t));
        if (items == NULL) return -1;
        bucket->items = items;
        bucket->capacity = capacity;
    }
    bucket->items[bucket->size++] = node;
    return 0;
}

/* Buckets used round and round at most (more: the edges' costs spread too far for
 * buckets, and the heap is used). */
#define MAX_BUCKETS 65536

/* graph(indptr, indices, edge_cost, edge_length, seeds, seed_cost, seed_length, wanted)
 * -> bytes (3 float64 per node): Dijkstra over a graph in compressed rows (int64
 * indptr/indices, float64 costs and lengths per edge) from several seeds at once, each
 * with a cost and a length already run up; per node its cheapest cost, the length along
 * that route and the index of the seed it came from (inf, inf, -1: not reached). Stops
 * once every `wanted` node (int64) is closed. */
static PyObject *graph(PyObject *self, PyObject *args) {
    Py_buffer b_indptr, b_indices, b_cost, b_length, b_seeds, b_seed_cost, b_seed_length, b_wanted;
    (void)self;
    if (!PyArg_ParseTuple(args, "y*y*y*y*y*y*y*y*", &b_indptr, &b_indices, &b_cost, &b_length,
                          &b_seeds, &b_seed_cost, &b_seed_length, &b_wanted))
        return NULL;
    PyObject *result = NULL;
    uint8_t *state = NULL, *want = NULL;
    Heap heap = {NULL, 0, 0};
    Py_ssize_t nodes = b_indptr.len / (Py_ssize_t)sizeof(int64_t) - 1;
    Py_ssize_t edges = b_indices.len / (Py_ssize_t)sizeof(int64_t);
    Py_ssize_t seeds = b_seeds.len / (Py_ssize_t)sizeof(int64_t);
    Py_ssize_t wanted_count = b_wanted.len / (Py_ssize_t)sizeof(int64_t);
    const int64_t *indptr = b_indptr.buf, *indices = b_indices.buf, *seed = b_seeds.buf;
    const int64_t *wanted = b_wanted.buf;
    const double *edge_cost = b_cost.buf, *edge_length = b_length.buf;
    const double *seed_cost = b_seed_cost.buf, *seed_length = b_seed_length.buf;
    if (nodes < 0 || b_cost.len != edges * (Py_ssize_t)sizeof(double) ||
        b_length.len != b_cost.len || indptr[nodes] != edges ||
        b_seed_cost.len != seeds * (Py_ssize_t)sizeof(double) ||
        b_seed_length.len != b_seed_cost.len) {
        PyErr_SetString(PyExc_ValueError, "inconsistent graph or seed arrays");
        goto finish;
    }
    for (Py_ssize_t i = 0; i < edges; i++) {
        if (indices[i] < 0 || indices[i] >= nodes) {
            PyErr_SetString(PyExc_IndexError, "edge to a node outside the graph");
            goto finish;
        }
    }
    for (Py_ssize_t i = 0; i < seeds; i++) {
        if (seed[i] < 0 || seed[i] >= nodes) {
            PyErr_SetString(PyExc_IndexError, "seed outside the graph");
            goto finish;
        }
    }
    for (Py_ssize_t i = 0; i < wanted_count; i++) {
        if (wanted[i] < 0 || wanted[i] >= nodes) {
            PyErr_SetString(PyExc_IndexError, "wanted node outside the graph");
            goto finish;
        }
    }
    state = calloc((size_t)nodes + 1, 1);
    want = calloc((size_t)nodes + 1, 1);
    result = PyBytes_FromStringAndSize(NULL, 3 * nodes * (Py_ssize_t)sizeof(double));
    if (state == NULL || want == NULL || result == NULL) {
        Py_CLEAR(result);
        PyErr_NoMemory();
        goto finish;
    }
    double *out = (double *)PyBytes_AS_STRING(result);
    int failed = 0;
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = 0; i < nodes; i++) {
        out[3 * i] = out[3 * i + 1] = INFINITY;
        out[3 * i + 2] = -1.0;
    }
    int64_t remaining = 0;
    for (Py_ssize_t i = 0; i < wanted_count; i++) {
        if (!want[wanted[i]]) {
            want[wanted[i]] = 1;
            remaining++;
        }
    }
    /* The bucket width: a little under the cheapest edge (rounding must not put a
     * node pushed from the lowest bucket into that bucket again). */
    double cheapest = INFINITY, dearest = 0.0, seed_low = INFINITY, seed_high = -INFINITY;
    for (Py_ssize_t e = 0; e < edges; e++) {
        if (edge_cost[e] < cheapest) cheapest = edge_cost[e];
        if (edge_cost[e] > dearest) dearest = edge_cost[e];
    }
    for (Py_ssize_t i = 0; i < seeds; i++) {
        if (seed_cost[i] < seed_low) seed_low = seed_cost[i];
        if (seed_cost[i] > seed_high) seed_high = seed_cost[i];
    }
    double spread = seeds > 0 ? fmax(dearest, seed_high - seed_low) : dearest;
    double bucket_width = 0.999 * cheapest;
    size_t bucket_count = 0;
    if (edges > 0 && isfinite(spread) && bucket_width > 0.0 && spread / bucket_width < MAX_BUCKETS - 2)
        bucket_count = (size_t)(spread / bucket_width) + 2;
    if (bucket_count > 0) {
        Bucket *buckets = calloc(bucket_count, sizeof(Bucket));
        failed = buckets == NULL;
        size_t queued = 0;
        int64_t lowest = 0;
        for (Py_ssize_t i = 0; i < seeds && !failed; i++) {
            int64_t node = seed[i];
            if (seed_cost[i] < out[3 * node]) {
                out[3 * node] = seed_cost[i];
                out[3 * node + 1] = seed_length[i];
                out[3 * node + 2] = (double)i;
            }
        }
        if (!failed && seeds > 0) lowest = (int64_t)floor(seed_low / bucket_width);
        for (Py_ssize_t i = 0; i < seeds && !failed; i++) {
            int64_t node = seed[i];
            if ((double)i != out[3 * node + 2]) continue; /* a cheaper seed of the node */
            int64_t k = (int64_t)floor(out[3 * node] / bucket_width);
            failed = bucket_push(&buckets[(size_t)k % bucket_count], node) < 0;
            queued++;
        }
        while (!failed && queued > 0 && remaining > 0) {
            Bucket *bucket = &buckets[(size_t)lowest % bucket_count];
            /* Nothing is pushed into the lowest bucket while it is emptied. */
            for (size_t at = 0; at < bucket->size && !failed && remaining > 0; at++) {
                int64_t node = bucket->items[at];
                queued--;
                if (state[node]) continue;
                if ((int64_t)floor(out[3 * node] / bucket_width) != lowest) continue; /* stale */
                state[node] = 1;
                if (want[node]) remaining--;
                double g0 = out[3 * node];
                for (int64_t e = indptr[node]; e < indptr[node + 1]; e++) {
                    int64_t next = indices[e];
                    if (state[next]) continue;
                    double g = g0 + edge_cost[e];
                    if (g < out[3 * next]) {
                        out[3 * next] = g;
                        out[3 * next + 1] = out[3 * node + 1] + edge_length[e];
                        out[3 * next + 2] = out[3 * node + 2];
                        int64_t k = (int64_t)floor(g / bucket_width);
                        if (bucket_push(&buckets[(size_t)k % bucket_count], next) < 0) {
                            failed = 1;
                            break;
                        }
                        queued++;
                    }
                }
            }
            bucket->size = 0;
            lowest++;
        }
        if (buckets != NULL) {
            for (size_t k = 0; k < bucket_count; k++) free(buckets[k].items);
            free(buckets);
        }
    } else {
        for (Py_ssize_t i = 0; i < seeds && !failed; i++) {
            int64_t node = seed[i];
            if (seed_cost[i] < out[3 * node]) {
                out[3 * node] = seed_cost[i];
                out[3 * node + 1] = seed_length[i];
                out[3 * node + 2] = (double)i;
                failed = heap_push(&heap, (Entry){seed_cost[i], seed_cost[i], node}) < 0;
            }
        }
        while (!failed && heap.size > 0 && remaining > 0) {
            Entry entry = heap_pop(&heap);
            int64_t node = entry.cell;
            if (state[node] || entry.g > out[3 * node]) continue;
            state[node] = 1;
            if (want[node]) remaining--;
            for (int64_t e = indptr[node]; e < indptr[node + 1]; e++) {
                int64_t next = indices[e];
                if (state[next]) continue;
                double g = entry.g + edge_cost[e];
                if (g < out[3 * next]) {
                    out[3 * next] = g;
                    out[3 * next + 1] = out[3 * node + 1] + edge_length[e];
                    out[3 * next + 2] = out[3 * node + 2];
                    if (heap_push(&heap, (Entry){g, g, next}) < 0) {
                        failed = 1;
                        break;
                    }
                }
            }
        }
    }
    Py_END_ALLOW_THREADS
    if (failed) {
        Py_CLEAR(result);
        PyErr_NoMemory();
    }

finish:
    free(heap.items);
    free(state);
    free(want);
    PyBuffer_Release(&b_indptr);
    PyBuffer_Release(&b_indices);
    PyBuffer_Release(&b_cost);
    PyBuffer_Release(&b_length);
    PyBuffer_Release(&b_seeds);
    PyBuffer_Release(&b_seed_cost);
    PyBuffer_Release(&b_seed_length);
    PyBuffer_Release(&b_wanted);
    return result;
}

static PyMethodDef methods[] = {
    {"search", search, METH_VARARGS,
     "search(cost, width, lut, start, goal, heuristic_scale) -> (total, cells) or None\n\n"
     "A* over an 8-connected uint8 costmap; see navseq.sim.planner."},
    {"distances", distances, METH_VARARGS,
     "distances(cost, width, lut, start, targets) -> bytes of float64 lengths in cells\n\n"
     "One Dijkstra search from start until every target is reached (inf: unreachable)."},
    {"routes", routes, METH_VARARGS,
     "routes(cost, width, lut, start, targets, anchor_cells) -> bytes of float64 triples\n\n"
     "As distances, with each route's departure and arrival anchor cells (-1: no route)."},
    {"local", local, METH_VARARGS,
     "local(cost, width, lut, start, bound, queries, anchor_cells) -> bytes of float64 "
     "triples\n\nDijkstra from start up to cost bound: per query length, cost, anchor."},
    {"graph", graph, METH_VARARGS,
     "graph(indptr, indices, edge_cost, edge_length, seeds, seed_cost, seed_length, "
     "wanted) -> bytes of float64 triples\n\nMulti-seed Dijkstra over a graph."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_astar", "Compiled A* search for navseq's global planner.", -1,
    methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__astar(void) { return PyModule_Create(&module); }
