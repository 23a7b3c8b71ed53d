/* Local stepping (docs/sundials-ode.md, local stepping): the scene integrated cluster by cluster.
 *
 * Bodies joined by links, stiffness blocks, mass couplings or closed contacts form a cluster; clusters interact only through open
 * penalty contacts (gap < 0: no force). Each cluster is integrated by its own CVODE or ARKODE
 * instance on its sub-model (martello_model_subset), so that a step, an event and a restart cost
 * O(cluster), not O(n). Inside a cluster everything is as on the whole scene (c/sundials_ode.c,
 * c/ode_events.c): roots, events inside the steps, the observer's hand-overs (with the cluster's
 * maps to the scene's numbering).
 *
 * The scheduler always advances the cluster of least time by one step (CV_ONE_STEP, ARK_ONE_STEP;
 * a binary heap on the times). A cluster's last step is TENTATIVE: its hand-overs to the observer
 * and its commit are made only when it steps again, when an event cuts it, or at t_end. When a
 * cluster steps, it has the least time, so every other cluster's last step began at or before its
 * own: every check and every output row needs only each cluster's last step, on its interpolant
 * (CVodeGetDky, ARKStepGetDky), and a cut at t* inside a tentative step undoes nothing (no
 * rollback beyond one step).
 *
 * Gaps between clusters: each open contact joining two clusters X, Y is checked through a time
 * (checked[j]); after X or Y moves, its gap delta and rate are tested on [checked, min(t_X, t_Y)]
 * on both interpolants (a sign change of the gap, or of the rate with the gap closed at its
 * extremum: the two roots per contact of c/ode_events.c). A root is bisected to adjacent doubles;
 * t* is its open side (delta(t*) < 0: no force at the cut). X and Y are then frozen at t* (their
 * time is t*) and merge when t* is the least time of all clusters: no earlier root can then reach
 * them. An earlier root on a frozen cluster replaces its pending event; its former partner is
 * unfrozen (its last step was never cut).
 * Release: a closed contact of a cluster that opens inside its last step (delta >= 0 at the start,
 * < 0 at the end), and whose opening splits the cluster's graph, freezes it at the first open
 * time; it then splits into its connected components. A missed split (a contact that opens and
 * closes inside one step) costs speed, never accuracy: the contact stays in the sub-model.
 * Output rows: row t_k is written when the least time passes it, every cluster's last step then
 * holding t_k: the scene's state assembled there, committed in the scene's evaluator (the store
 * of the element states between clusters) and recorded (martello_observer_row). t = 0 and t_end,
 * where every cluster stands at one time, are the run's samples of the energy balance. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <nvector/nvector_serial.h>

#include "martello.h"
#include "martello_internal.h"
#include "ode_events.h"
#include "sundials_ode.h"

enum { PEND_NONE, PEND_MERGE, PEND_SPLIT };

typedef struct {
  ode_problem P;              /* CVODE on the sub-model; P.E.ev holds its element states */
  martello_model *model;      /* the sub-model */
  martello_subset_map map;    /* sub -> scene numbering (ascending; fixed nodes among them) */
  int nfree, *fk;             /* its free nodes: sub nodes fk[0..nfree) */
  N_Vector y, yq;             /* the state at t1; the interpolant at tq */
  SUNMatrix J;
  SUNLinearSolver LS;
  double t0, t1, tret, tq;    /* the tentative step [t0, t1]; CVODE stands at tret >= t1 */
  int stepped;                /* 0: no step since its start (its state at t0 = t1 is y) */
  int again;                  /* the tentative step ends with an event of its own at t1 */
  int kink;
  double t_stop;
  int *found;                 /* the roots' flags */
  int pend, partner;          /* a pending merge (with partner) or split at tp */
  double tp;
  int hpos;                   /* place in the heap */
  int queued;                 /* in D->todo */
} cluster;

typedef struct {
  ode_problem S;              /* the scene: topology, its evaluator (the store), the observer */
  martello_model *model;
  martello_run *run;
  SUNContext ctx;
  int n, nc;
  cluster **cl;               /* by slot; NULL: free */
  int ncl;
  int *heap, nheap;           /* slots by time; hkey[k] the time of heap[k] (contiguous: */
  double *hkey;               /* the sifts read no cluster) */
  int *node_cl, *node_loc;    /* free node -> its cluster's slot and its index there */
  int *nd_first, *nd_con;     /* node -> its contacts */
  int *grp, *gr_first, *gr_node; /* free node -> its group (nodes joined for good: links, blocks,
                                 * couplings; martello_model_clusters), group -> its nodes */
  double *checked;            /* per contact joining two clusters: checked through */
  double *u0, *ys;            /* the scene's initial u; its state (interleaved) */
  int *mark, *list, *stack;   /* graph work */
  int *todo, ntodo;
  int *slots, nslots;         /* the free slots */
  int *ev_n;                  /* per free node: events in a row of its cluster at one time, */
  double *ev_t;               /* the last at ev_t */           /* clusters whose time rose (unfrozen): their contacts to check */
  double t_end;
} driver;

#define fail(D, ...) oe_fail(&(D)->S.E, __VA_ARGS__)

/* ---- the heap of clusters by time (its pending event's, else its last step's end) ---------- */

static double t_of(const cluster *c) { return c->pend ? c->tp : c->t1; }

static int heap_less(driver *D, int a, int b) { return D->hkey[a] < D->hkey[b]; }

static void heap_swap(driver *D, int a, int b) {
  int s = D->heap[a];
  double t = D->hkey[a];
  D->heap[a] = D->heap[b];
  D->hkey[a] = D->hkey[b];
  D->heap[b] = s;
  D->hkey[b] = t;
  D->cl[D->heap[a]]->hpos = a;
  D->cl[D->heap[b]]->hpos = b;
}

static void heap_fix(driver *D, int k) {
  while (k > 0 && heap_less(D, k, (k - 1) / 2)) {
    heap_swap(D, k, (k - 1) / 2);
    k = (k - 1) / 2;
  }
  for (;;) {
    int l = 2 * k + 1, r = l + 1, m = k;
    if (l < D->nheap && heap_less(D, l, m)) m = l;
    if (r < D->nheap && heap_less(D, r, m)) m = r;
    if (m == k) return;
    heap_swap(D, k, m);
    k = m;
  }
}

/* Cluster c's time changed: its place. */
static void heap_update(driver *D, cluster *c) {
  D->hkey[c->hpos] = t_of(c);
  heap_fix(D, c->hpos);
}

static void heap_push(driver *D, int slot) {
  D->heap[D->nheap] = slot;
  D->hkey[D->nheap] = t_of(D->cl[slot]);
  D->cl[slot]->hpos = D->nheap++;
  heap_fix(D, D->nheap - 1);
}

static void heap_remove(driver *D, int slot) {
  int k = D->cl[slot]->hpos;
  heap_swap(D, k, --D->nheap);
  if (k < D->nheap) heap_fix(D, k);
}

/* The scene's number of free node q of cluster c. */
static inline int free_node(const cluster *c, int q) { return c->map.node[c->fk[q]]; }

/* ---- a cluster's state on its last step ----------------------------------------------------- */

/* The cluster's state (interleaved u, v of its sub nodes) at t in [t0, t1]. */
static const double *state_at(driver *D, cluster *c, double t, int *st) {
  *st = MARTELLO_OK;
  if (t >= c->t1 || !c->stepped) return N_VGetArrayPointer(c->y);
  if (t != c->tq) {
    if ((*st = ode_problem_interpolant(&c->P, t, 0, c->yq)) != MARTELLO_OK) return NULL;
    c->tq = t;
  }
  (void)D;
  return N_VGetArrayPointer(c->yq);
}

/* delta_j (deriv 0) or its rate (1) at t, each node on its cluster's last step. */
static double gap_at(driver *D, int j, double t, int deriv, int *st) {
  const martello_rows *r = &D->S.E.con;
  double s = 0.0;
  *st = MARTELLO_OK;
  for (int k = r->first[j]; k < r->first[j + 1]; k++) {
    const int i = r->node[k];
    double x = deriv ? 0.0 : D->u0[i];
    if (!D->S.E.fixed[i]) {
      const double *y = state_at(D, D->cl[D->node_cl[i]], t, st);
      if (*st != MARTELLO_OK) return 0.0;
      x = y[2 * D->node_loc[i] + deriv];
    }
    s += r->coef[k] * x;
  }
  return deriv ? s : s - D->S.E.gap[j];
}

/* Cluster c's nodes' state at t into D->ys (interleaved, the scene's numbering). */
static int cluster_state(driver *D, cluster *c, double t) {
  int st;
  const double *y = state_at(D, c, t, &st);
  if (st != MARTELLO_OK) return st;
  for (int q = 0; q < c->nfree; q++) {
    const int k = c->fk[q], i = c->map.node[k];
    D->ys[2 * i] = y[2 * k];
    D->ys[2 * i + 1] = y[2 * k + 1];
  }
  return MARTELLO_OK;
}

/* The scene's state at t into D->ys, every cluster on its last step. */
static int scene_state(driver *D, double t) {
  for (int s = 0; s < D->ncl; s++) {
    int st = D->cl[s] ? cluster_state(D, D->cl[s], t) : MARTELLO_OK;
    if (st != MARTELLO_OK) return st;
  }
  return MARTELLO_OK;
}

/* ---- clusters: start, cut, stop ------------------------------------------------------------- */

/* A cluster of the free nodes nodes[0..m) at t, its state from D->ys, its element states from the
 * scene's evaluator (the store); its stop time, and its place in the heap (its slot into *at). */
static int start_cluster(driver *D, const int *nodes, int m, double t, int *at) {
  int st;
  /* at most one cluster per free node: a slot is always free */
  const int slot = D->slots[--D->nslots];
  cluster *c = calloc(1, sizeof *c);
  if (!c) return oe_fail_memory(&D->S.E, "a cluster of the local stepping", (double)sizeof *c);
  D->cl[slot] = c;
  c->pend = PEND_NONE;
  if ((st = martello_model_subset(D->model, m, nodes, &c->model, &c->map)) != MARTELLO_OK) {
    char line[480];
    martello_model_message(D->model, line, (int)sizeof line);
    return fail(D, st, "local stepping: the sub-model of a cluster of %d nodes failed: %s", m, line);
  }
  c->nfree = 0;
  c->fk = malloc((size_t)m * sizeof(int));
  if (!c->fk) return oe_fail_memory(&D->S.E, "a cluster of the local stepping", (double)m * sizeof(int));
  for (int k = 0; k < c->map.n_nodes; k++) {
    const int i = c->map.node[k];
    if (D->S.E.fixed[i]) continue;
    if (c->nfree == m) return fail(D, MARTELLO_ERR_EXTERNAL, "local stepping: a sub-model has more free nodes than asked");
    c->fk[c->nfree++] = k;
    D->node_cl[i] = slot;
    D->node_loc[i] = k;
  }
  if (c->nfree != m) return fail(D, MARTELLO_ERR_EXTERNAL, "local stepping: a sub-model has %d free nodes of %d", c->nfree, m);
  if (at) *at = slot;
  if ((st = ode_problem_setup(&c->P, c->model, D->run)) != MARTELLO_OK) return st;
  ode_events *E = &c->P.E;
  E->g_node = c->map.node;
  E->g_con = c->map.contact;
  E->g_link = c->map.link;
  if ((st = martello_eval_state_transfer(D->S.E.ev, E->ev, &c->map, 1)) != MARTELLO_OK)
    return fail(D, st, "local stepping: the element states of a cluster could not be taken");
  c->y = N_VNew_Serial(c->P.N, D->ctx);
  c->yq = N_VNew_Serial(c->P.N, D->ctx);
  E->ytmp = N_VNew_Serial(c->P.N, D->ctx);
  E->ytd = N_VNew_Serial(c->P.N, D->ctx);
  E->yrow = N_VNew_Serial(c->P.N, D->ctx);
  c->found = calloc((size_t)oe_nroots(E) + 1, sizeof(int));
  if (!c->y || !c->yq || !E->ytmp || !E->ytd || !E->yrow || !c->found)
    return oe_fail_memory(&D->S.E, "the state vectors of a cluster", -1.0);
  double *y = N_VGetArrayPointer(c->y);
  for (int k = 0; k < E->n; k++) {
    const int i = c->map.node[k];
    y[2 * k] = D->S.E.fixed[i] ? D->u0[i] : D->ys[2 * i];
    y[2 * k + 1] = D->S.E.fixed[i] ? 0.0 : D->ys[2 * i + 1];
  }
  if (t == 0.0) {
    oe_gather(E, y, E->u, E->v);
    if ((st = oe_initial_contacts(E, E->u, E->v)) != MARTELLO_OK) return st;
  }
  if ((st = ode_problem_prepare_restart(&c->P, t, y)) != MARTELLO_OK) return st;
  if ((st = ode_problem_create(&c->P, D->ctx, c->y, &c->J, &c->LS)) != MARTELLO_OK) return st;
  if (t > 0.0 && (st = ode_problem_restart(&c->P, t, c->y)) != MARTELLO_OK) return st;
  oe_accepted(E, y);
  c->t0 = c->t1 = c->tret = t;
  c->tq = -1.0;
  c->t_stop = oe_next_stop(E, t, D->t_end, &c->kink);
  if ((st = ode_problem_stop(&c->P, c->t_stop)) != MARTELLO_OK) return st;
  heap_push(D, slot);
  return MARTELLO_OK;
}

static void free_cluster(driver *D, int slot) {
  cluster *c = D->cl[slot];
  if (!c) return;
  ode_events *E = &c->P.E;
  if (c->LS) SUNLinSolFree(c->LS);
  if (c->J) SUNMatDestroy(c->J);
  N_Vector *vs[] = {&c->y, &c->yq, &E->ytmp, &E->ytd, &E->yrow};
  for (size_t k = 0; k < sizeof vs / sizeof vs[0]; k++)
    if (*vs[k]) N_VDestroy(*vs[k]);
  ode_problem_release(&c->P);
  martello_subset_map_free(&c->map);
  if (c->model) martello_model_free(&c->model);
  free(c->found);
  free(c->fk);
  free(c);
  D->cl[slot] = NULL;
  D->slots[D->nslots++] = slot;
}

/* The tentative step [t0, t1] of c made final up to tf <= t1: the events inside it, the works,
 * extrema and peaks handed to the observer, the state committed, or, at its own event at t1, the
 * event made there (and the restart, unless cut). cut = 1: the driver ends the cluster at tf (a
 * merge or a split); its own event at t1 > tf is dropped (the new clusters find it afresh). */
static int finalize(driver *D, cluster *c, double tf, int cut) {
  ode_events *E = &c->P.E;
  double *y = N_VGetArrayPointer(c->y);
  int st, own = c->again && tf == c->t1;
  if (!c->stepped) return MARTELLO_OK;
  if (tf < c->t1) {
    if (tf < c->tret && (st = ode_problem_interpolant(&c->P, tf, 0, c->y)) != MARTELLO_OK) return st;
    for (int j = 0; j < E->nc; j++) E->act[j] = ACT_NONE;
    for (int s = 0; s < E->nsw; s++) E->sw_hit[s] = 0;
  }
  const int at_event = cut || c->again;
  if ((st = oe_inner_events(E, c->t0, tf, y)) != MARTELLO_OK) return st;
  if ((st = oe_stretch(E, c->t0, tf, y, at_event)) != MARTELLO_OK) return st;
  oe_keep_end_rates(E, !at_event);
  E->t_now = tf;
  if (own) {
    if ((st = oe_restart_progress(E, tf)) != MARTELLO_OK) return st;
    if ((st = ode_problem_flush_counts(&c->P)) != MARTELLO_OK) return st;
    if ((st = ode_problem_prepare_restart(&c->P, tf, y)) != MARTELLO_OK) return st;
  } else {
    oe_gather(E, y, E->u, E->v);
    if ((st = oe_commit(E, E->u, E->v)) != MARTELLO_OK) return fail(D, st, "local stepping: commit failed");
    if ((st = oe_hand_work(E)) != MARTELLO_OK) return st;
  }
  oe_accepted(E, y);
  c->t0 = c->t1 = tf;
  c->tq = -1.0;
  c->stepped = 0;
  if (own && !cut && (st = ode_problem_restart(&c->P, tf, c->y)) != MARTELLO_OK) return st;
  if (!cut && (own || c->tret >= c->t_stop)) {
    c->t_stop = oe_next_stop(E, tf, D->t_end, &c->kink);
    if ((st = ode_problem_stop(&c->P, c->t_stop)) != MARTELLO_OK) return st;
  }
  c->again = 0;
  return MARTELLO_OK;
}

/* c ends at tf (cut, or t_end): its last step made final there, its state into D->ys, its
 * element states into the scene's store, its counters to the run; freed. */
static int stop_cluster(driver *D, int slot, double tf) {
  cluster *c = D->cl[slot];
  int st = finalize(D, c, tf, 1);
  if (st == MARTELLO_OK) st = ode_problem_flush_counts(&c->P);
  if (st == MARTELLO_OK && (st = martello_eval_state_transfer(D->S.E.ev, c->P.E.ev, &c->map, 0)) != MARTELLO_OK)
    st = fail(D, st, "local stepping: the element states of a cluster could not be given back");
  if (st != MARTELLO_OK) return st;
  const double *y = N_VGetArrayPointer(c->y);
  for (int q = 0; q < c->nfree; q++) {
    const int k = c->fk[q], i = c->map.node[k];
    D->ys[2 * i] = y[2 * k];
    D->ys[2 * i + 1] = y[2 * k + 1];
    D->node_cl[i] = -1;
  }
  heap_remove(D, slot);
  free_cluster(D, slot);
  return MARTELLO_OK;
}

/* ---- the graph: bonds (groups, closed contacts) and components -------------------------------- */

/* Whether contact j is closed (a bond) in the state D->ys. */
static int closed_in(driver *D, int j) {
  const martello_rows *r = &D->S.E.con;
  double s = 0.0;
  for (int k = r->first[j]; k < r->first[j + 1]; k++) {
    const int i = r->node[k];
    s += r->coef[k] * (D->S.E.fixed[i] ? D->u0[i] : D->ys[2 * i]);
  }
  return s - D->S.E.gap[j] >= 0.0;
}

/* Marks group g's nodes (all of mark want: a group never splits) want + 1, onto the stack. */
static int push_group(driver *D, int g, int want, int top) {
  for (int p = D->gr_first[g]; p < D->gr_first[g + 1]; p++) {
    D->mark[D->gr_node[p]] = want + 1;
    D->stack[top++] = D->gr_node[p];
  }
  return top;
}

/* The component of free node i0 among the nodes with mark[i] == want, bonds of the state D->ys
 * (the groups, and the closed contacts but skip, a contact not counted as a bond, or -1): marked
 * want + 1, listed in D->list. */
static int component(driver *D, int i0, int want, int skip) {
  int top = push_group(D, D->grp[i0], want, 0), m = 0;
  while (top > 0) {
    const int i = D->stack[--top];
    D->list[m++] = i;
    for (int p = D->nd_first[i]; p < D->nd_first[i + 1]; p++) {
      const int j = D->nd_con[p];
      if (j == skip || !closed_in(D, j)) continue;
      for (int k = D->S.E.con.first[j]; k < D->S.E.con.first[j + 1]; k++) {
        const int b = D->S.E.con.node[k];
        if (!D->S.E.fixed[b] && D->mark[b] == want) top = push_group(D, D->grp[b], want, top);
      }
    }
  }
  return m;
}

/* ---- events between clusters -------------------------------------------------------------- */

/* The other cluster of contact j seen from slot s (-1: none; j inside s or on fixed nodes). */
static int other_cluster(driver *D, int j, int s) {
  const martello_rows *r = &D->S.E.con;
  for (int k = r->first[j]; k < r->first[j + 1]; k++) {
    const int i = r->node[k];
    if (!D->S.E.fixed[i] && D->node_cl[i] != s) return D->node_cl[i];
  }
  return -1;
}

static void unfreeze(driver *D, int s) {
  cluster *c = D->cl[s];
  c->pend = PEND_NONE;
  heap_update(D, c);
  if (!c->queued) {
    c->queued = 1;
    D->todo[D->ntodo++] = s;
  }
}

/* An event of kind at t for slots a (and b for a merge): it replaces later pending ones of theirs;
 * an earlier or simultaneous one of either stays (this one is found again after it). 1 if set. */
static int pend_event(driver *D, int kind, int a, int b, double t) {
  cluster *ca = D->cl[a], *cb = b >= 0 ? D->cl[b] : NULL;
  if ((ca->pend && ca->tp <= t) || (cb && cb->pend && cb->tp <= t)) return 0;
  int who[2] = {a, b};
  for (int q = 0; q < 2; q++) {
    if (who[q] < 0) continue;
    cluster *c = D->cl[who[q]];
    if (c->pend == PEND_MERGE && c->partner != a && c->partner != b) unfreeze(D, c->partner);
  }
  ca->pend = kind;
  ca->partner = b;
  ca->tp = t;
  heap_update(D, ca);
  if (cb) {
    cb->pend = kind;
    cb->partner = a;
    cb->tp = t;
    heap_update(D, cb);
  }
  return 1;
}

/* The first time in [a, b] where contact j is closed, delta(a) < 0 <= delta(b): bisected to
 * adjacent doubles; its open side a into *t (the cut, where no contact force acts). */
static int bisect_closing(driver *D, int j, double a, double b, double *t) {
  int st;
  for (;;) {
    const double m = 0.5 * (a + b);
    if (!(m > a && m < b)) break;
    const double g = gap_at(D, j, m, 0, &st);
    if (st != MARTELLO_OK) return st;
    if (g >= 0.0) b = m; else a = m;
  }
  *t = a;
  return MARTELLO_OK;
}

/* Contact j between slots s and o over [checked, min(t_s, t_o)]: a root pends a merge. The gap
 * is tested at the ends of the interval and, where its rate changes sign inside, at the rate's
 * root (the gap's extremum, bisected): the two root functions per contact of c/ode_events.c,
 * which see a closing between the ends of a step unless the gap has two extrema inside it. */
static int check_contact(driver *D, int j, int s, int o) {
  int st;
  const double lo = D->checked[j], hi = fmin(t_of(D->cl[s]), t_of(D->cl[o]));
  if (!(hi > lo)) return MARTELLO_OK;
  /* open at lo by construction (checked through it, or a cut's open side): its gap there on a
   * new interpolant may differ by rounding, and is not tested again (a merge and a split at one
   * time would follow each other) */
  const double r0 = gap_at(D, j, lo, 1, &st);
  if (st != MARTELLO_OK) return st;
  const double r1 = gap_at(D, j, hi, 1, &st);
  if (st != MARTELLO_OK) return st;
  double seg[3] = {lo, hi, hi};
  int parts = 1;
  if ((r0 > 0.0 && r1 < 0.0) || (r0 < 0.0 && r1 > 0.0)) {
    double a = lo, b = hi;
    for (;;) {
      const double m = 0.5 * (a + b);
      if (!(m > a && m < b)) break;
      const double r = gap_at(D, j, m, 1, &st);
      if (st != MARTELLO_OK) return st;
      if ((r > 0.0) == (r0 > 0.0)) a = m; else b = m;
    }
    seg[1] = b;
    parts = 2;
  }
  for (int p = 0; p < parts; p++) {
    const double gb = gap_at(D, j, seg[p + 1], 0, &st);
    if (st != MARTELLO_OK) return st;
    if (gb >= 0.0) {
      double t;
      if ((st = bisect_closing(D, j, seg[p], seg[p + 1], &t)) != MARTELLO_OK) return st;
      if (pend_event(D, PEND_MERGE, s, o, t)) D->checked[j] = t;
      return MARTELLO_OK;
    }
  }
  D->checked[j] = hi;
  return MARTELLO_OK;
}

/* Every contact joining slot s to another cluster, checked. */
static int check_cluster(driver *D, int s) {
  cluster *c = D->cl[s];
  for (int q = 0; q < c->nfree; q++) {
    const int i = free_node(c, q);
    for (int p = D->nd_first[i]; p < D->nd_first[i + 1]; p++) {
      const int j = D->nd_con[p], o = other_cluster(D, j, s);
      if (o < 0) continue;
      int st = check_contact(D, j, s, o);
      if (st != MARTELLO_OK) return st;
      if (!D->cl[s]) return MARTELLO_OK;
    }
  }
  return MARTELLO_OK;
}

/* The contacts of slot s with other clusters checked through t (a cluster started at t). */
static void reset_checked(driver *D, int s, double t) {
  cluster *c = D->cl[s];
  for (int q = 0; q < c->nfree; q++) {
    const int i = free_node(c, q);
    for (int p = D->nd_first[i]; p < D->nd_first[i + 1]; p++) {
      const int j = D->nd_con[p];
      if (other_cluster(D, j, s) >= 0) D->checked[j] = t;
    }
  }
}

/* A closed contact inside slot s's tentative step that opens, splitting its graph: a pending split
 * at its first open time. */
static int check_release(driver *D, int s) {
  cluster *c = D->cl[s];
  ode_events *E = &c->P.E;
  int st;
  double t_split = HUGE_VAL;
  for (int q = 0; q < E->nc; q++) {
    const int j = c->map.contact[q];
    if (other_cluster(D, j, s) >= 0) continue;
    const double g1 = gap_at(D, j, c->t1, 0, &st);
    if (st != MARTELLO_OK) return st;
    if (g1 >= 0.0) continue;
    const double g0 = gap_at(D, j, c->t0, 0, &st);
    if (st != MARTELLO_OK) return st;
    if (!(g0 >= 0.0)) continue;
    /* the first open time: delta(a) >= 0 > delta(b) */
    double a = c->t0, b = c->t1;
    for (;;) {
      const double m = 0.5 * (a + b);
      if (!(m > a && m < b)) break;
      const double g = gap_at(D, j, m, 0, &st);
      if (st != MARTELLO_OK) return st;
      if (g >= 0.0) a = m; else b = m;
    }
    /* the cut: its first open time, or the step's end when the step ends with an event of its
     * own (the contact's separation where it is a root: a cut before would drop it) */
    const double tc = c->again ? c->t1 : b;
    if (!(tc < t_split)) continue;
    /* separating there (delta' < 0): a grazing contact that closes again at once stays inside
     * (a split and a merge at one time would follow each other without end) */
    const double rc = gap_at(D, j, tc, 1, &st);
    if (st != MARTELLO_OK) return st;
    if (!(rc < 0.0)) continue;
    /* does its opening split the cluster? its graph at b, contact j open */
    if ((st = cluster_state(D, c, b)) != MARTELLO_OK) return st;
    for (int q = 0; q < c->nfree; q++) D->mark[free_node(c, q)] = 0;
    const int m = component(D, free_node(c, 0), 0, -1);
    for (int q = 0; q < c->nfree; q++) D->mark[free_node(c, q)] = -1;
    if (m < c->nfree) t_split = tc;
  }
  if (t_split < HUGE_VAL) pend_event(D, PEND_SPLIT, s, -1, t_split);
  return MARTELLO_OK;
}

/* The pending event of slot s at its time, the least of all: a merge with its partner, or a split
 * into the components of its graph there; the new clusters start at tp. */
static int run_event(driver *D, int s) {
  cluster *c = D->cl[s];
  const double tp = c->tp;
  const int kind = c->pend, o = c->partner;
  int st, m = 0;
  /* merges and splits of the same nodes that recur without progress in time (within a few
   * ulps; other clusters may meet at one time by symmetry): the run fails rather than loop */
  for (int q = 0; q < c->nfree; q++) {
    const int i = free_node(c, q);
    D->ev_n[i] = tp - D->ev_t[i] <= 16.0 * DBL_EPSILON * fabs(tp) ? D->ev_n[i] + 1 : 0;
    D->ev_t[i] = tp;
    if (D->ev_n[i] > 64)
      return fail(D, MARTELLO_ERR_NOT_CONVERGED, "local stepping: the cluster of node %d merges and "
                  "splits at t = %.9e s without progress (a grazing contact?); set "
                  "analysis.local_stepping = false", i, tp);
  }
  int *nodes = D->stack + D->n;   /* the second half of the work stack */
  for (int q = 0; q < c->nfree; q++) nodes[m++] = free_node(c, q);
  if (kind == PEND_MERGE)
    for (int q = 0; q < D->cl[o]->nfree; q++) nodes[m++] = free_node(D->cl[o], q);
  if ((st = stop_cluster(D, s, tp)) != MARTELLO_OK) return st;
  if (kind == PEND_MERGE && (st = stop_cluster(D, o, tp)) != MARTELLO_OK) return st;
  int sl;
  if (kind == PEND_MERGE) {
    if ((st = start_cluster(D, nodes, m, tp, &sl)) != MARTELLO_OK) return st;
    reset_checked(D, sl, tp);
  } else {
    for (int k = 0; k < m; k++) D->mark[nodes[k]] = 0;
    for (int k = 0; k < m; k++) {
      if (D->mark[nodes[k]] != 0) continue;
      const int mc = component(D, nodes[k], 0, -1);
      if ((st = start_cluster(D, D->list, mc, tp, &sl)) != MARTELLO_OK) return st;
      reset_checked(D, sl, tp);
    }
    for (int k = 0; k < m; k++) D->mark[nodes[k]] = -1;
  }
  return MARTELLO_OK;
}

/* ---- a step of one cluster ------------------------------------------------------------------ */

static int step_cluster(driver *D, int s) {
  cluster *c = D->cl[s];
  ode_events *E = &c->P.E;
  int st;
  if ((st = finalize(D, c, c->t1, 0)) != MARTELLO_OK) return st;
  double tret = c->t1, *y = N_VGetArrayPointer(c->y);
  int flag = ode_problem_step(&c->P, D->t_end, c->y, &tret);
  if (flag < 0) {
    const double tcur = ode_problem_current_time(&c->P, c->t1);
    E->t_now = D->S.E.t_now = tcur;
    for (sunindextype k = 0; k < c->P.N; k++)
      if (!isfinite(y[k])) E->nan_seen = 1;
    if (E->nan_seen || !isfinite(tcur)) return martello_observer_fail(D->S.E.obs, MARTELLO_ERR_DIVERGED, tcur, NULL);
    return fail(D, MARTELLO_ERR_EXTERNAL, "%s failed at t = %.9e s in a cluster of %d nodes: %s (%s)",
                c->P.name, tcur, c->nfree, ode_problem_flag(&c->P, flag), c->P.msg);
  }
  E->nan_seen = 0;
  oe_new_step(E, tret);
  /* a step of the run's budget (the steps of all clusters add up) */
  if ((st = martello_observer_step(D->S.E.obs, D->S.E.t_now = c->t1)) != MARTELLO_OK) return st;
  int again = 0;
  double t_r = tret;
  if (flag == ODE_STEP_ROOT) {
    if ((st = ode_problem_root_info(&c->P, c->found)) != MARTELLO_OK) return st;
    again = oe_classify_roots(E, c->t1, tret, y, c->found, &t_r);
    if (again < 0) return again;
    if (!again) again = ode_problem_root_stays_zero(&c->P, y, c->found);
  }
  if (!again && flag == ODE_STEP_TSTOP && tret == c->t_stop && c->kink && c->t_stop < D->t_end) again = 1;
  if (!again) {
    again = oe_boundary_events(E, c->t1, tret, y, ode_problem_last_step(&c->P), &t_r);
    if (again < 0) return again;
  }
  if (again && t_r < tret && (st = ode_problem_interpolant(&c->P, t_r, 0, c->y)) != MARTELLO_OK) return st;
  c->t0 = c->t1;
  c->t1 = t_r;
  c->tret = tret;
  c->again = again;
  c->stepped = 1;
  c->tq = -1.0;
  heap_update(D, c);
  if ((st = check_release(D, s)) != MARTELLO_OK) return st;
  if ((st = check_cluster(D, s)) != MARTELLO_OK) return st;
  /* clusters unfrozen meanwhile: their time rose, their contacts are checked on */
  while (D->ntodo > 0) {
    const int o = D->todo[--D->ntodo];
    if (!D->cl[o]) continue;
    D->cl[o]->queued = 0;
    if (D->cl[o]->pend) continue;
    if (D->cl[o]->stepped && (st = check_release(D, o)) != MARTELLO_OK) return st;
    if (!D->cl[o]->pend && (st = check_cluster(D, o)) != MARTELLO_OK) return st;
  }
  return MARTELLO_OK;
}

/* ---- output ------------------------------------------------------------------------------------ */

/* Output row tk inside c's tentative step: the stretch [t0, tk] made final (inner events, works,
 * extrema, peaks, the state committed there), as the global run splits its steps at its rows
 * (c/ode_events.c oe_rows_inside: no event lies before t1, so a commit at tk and one at t1 leave
 * what one at t1 leaves); the step goes on from tk. At its end, the step made final. */
static int row_split(driver *D, cluster *c, double tk) {
  ode_events *E = &c->P.E;
  int st;
  if (!c->stepped || !(tk > c->t0)) return MARTELLO_OK;
  if (tk >= c->t1) return finalize(D, c, c->t1, 0);
  if ((st = ode_problem_interpolant(&c->P, tk, 0, E->yrow)) != MARTELLO_OK) return st;
  const double *y = N_VGetArrayPointer(E->yrow);
  if ((st = oe_inner_events(E, c->t0, tk, y)) != MARTELLO_OK) return st;
  if ((st = oe_stretch(E, c->t0, tk, y, 0)) != MARTELLO_OK) return st;
  oe_keep_end_rates(E, 1);
  oe_gather(E, y, E->u, E->v);
  if ((st = oe_commit(E, E->u, E->v)) != MARTELLO_OK) return fail(D, st, "local stepping: commit failed");
  if ((st = oe_hand_work(E)) != MARTELLO_OK) return st;
  oe_accepted(E, y);
  c->t0 = tk;
  return MARTELLO_OK;
}

/* The scene's state at t (every cluster's element states given to the store first) committed in
 * the scene's evaluator and handed to the observer: an output row (row = 1) or a sample. */
static int scene_sample(driver *D, double t, int k, int row) {
  int st;
  for (int s = 0; s < D->ncl; s++) {
    cluster *c = D->cl[s];
    if (c && row && (st = row_split(D, c, t)) != MARTELLO_OK) return st;
    if (c && (st = martello_eval_state_transfer(D->S.E.ev, c->P.E.ev, &c->map, 0)) != MARTELLO_OK)
      return fail(D, st, "local stepping: the element states of a cluster could not be given back");
  }
  if ((st = scene_state(D, t)) != MARTELLO_OK) return st;
  ode_events *S = &D->S.E;
  oe_gather(S, D->ys, S->u, S->v);
  if ((st = oe_commit(S, S->u, S->v)) != MARTELLO_OK) return fail(D, st, "local stepping: commit failed");
  return ode_problem_observe(&D->S, t, D->ys, k, row);
}

/* ---- the run ------------------------------------------------------------------------------------ */

/* What local stepping cannot run, refused by name with the fix. */
static int refuse(driver *D) {
  ode_events *S = &D->S.E;
  if (S->nr > 0)
    return fail(D, MARTELLO_ERR_UNSUPPORTED, "analysis.local_stepping: contact %d is rigid (lagrange or "
                "restitution); local stepping needs penalty contacts: set local_stepping = false",
                S->rig_con[0]);
  if (S->ncoupling > 0)
    return fail(D, MARTELLO_ERR_UNSUPPORTED, "analysis.local_stepping: the mass matrix couples nodes "
                "(%d couplings), which a cluster may cut; use a lumped mass or set local_stepping = false",
                S->ncoupling);
  return MARTELLO_OK;
}

/* Node -> its contacts; the groups: nodes a link, a stiffness block or a mass coupling joins
 * whatever the state (docs/sundials-ode.md, local stepping). */
static int incidence(driver *D) {
  ode_events *S = &D->S.E;
  const int n = D->n;
  double failed = 0.0;
  int ng = 0, st;
  D->nd_first = oe_take((size_t)n + 1, sizeof(int), &failed);
  D->grp = oe_take((size_t)n, sizeof(int), &failed);
  D->gr_node = oe_take((size_t)n, sizeof(int), &failed);
  if (failed > 0.0) return oe_fail_memory(S, "the node incidence of the local stepping", failed);
  if ((st = martello_model_clusters(D->model, NULL, D->grp, &ng)) != MARTELLO_OK) {
    char msg[256];
    martello_model_message(D->model, msg, (int)sizeof msg);
    return fail(D, st, "local stepping: the groups of the model: %s", msg);
  }
  D->gr_first = oe_take((size_t)ng + 1, sizeof(int), &failed);
  if (failed > 0.0) return oe_fail_memory(S, "the node incidence of the local stepping", failed);
  const martello_rows *rc = &S->con;
  for (int j = 0; j < D->nc; j++)
    for (int k = rc->first[j]; k < rc->first[j + 1]; k++) D->nd_first[rc->node[k] + 1]++;
  for (int i = 0; i < n; i++) {
    D->nd_first[i + 1] += D->nd_first[i];
    if (D->grp[i] >= 0) D->gr_first[D->grp[i] + 1]++;
  }
  for (int g = 0; g < ng; g++) D->gr_first[g + 1] += D->gr_first[g];
  D->nd_con = oe_take((size_t)D->nd_first[n], sizeof(int), &failed);
  int *at = oe_take((size_t)(n > ng ? n : ng), sizeof(int), &failed);
  if (failed > 0.0) { free(at); return oe_fail_memory(S, "the node incidence of the local stepping", failed); }
  for (int i = 0; i < n; i++) at[i] = D->nd_first[i];
  for (int j = 0; j < D->nc; j++)
    for (int k = rc->first[j]; k < rc->first[j + 1]; k++) D->nd_con[at[rc->node[k]]++] = j;
  for (int g = 0; g < ng; g++) at[g] = D->gr_first[g];
  for (int i = 0; i < n; i++)
    if (D->grp[i] >= 0) D->gr_node[at[D->grp[i]]++] = i;
  free(at);
  return MARTELLO_OK;
}

static int integrate(driver *D) {
  ode_events *S = &D->S.E;
  int st, n = D->n;
  double failed = 0.0;
  if ((st = refuse(D)) != MARTELLO_OK) return st;
  D->ncl = n;
  D->cl = oe_take((size_t)n, sizeof(cluster *), &failed);
  D->heap = oe_take((size_t)n, sizeof(int), &failed);
  D->hkey = oe_take((size_t)n, sizeof(double), &failed);
  D->node_cl = oe_take((size_t)n, sizeof(int), &failed);
  D->node_loc = oe_take((size_t)n, sizeof(int), &failed);
  D->checked = oe_take((size_t)D->nc, sizeof(double), &failed);
  D->u0 = oe_take((size_t)n, sizeof(double), &failed);
  D->ys = oe_take(2 * (size_t)n, sizeof(double), &failed);
  D->mark = oe_take((size_t)n, sizeof(int), &failed);
  D->list = oe_take((size_t)n, sizeof(int), &failed);
  D->stack = oe_take(2 * (size_t)n, sizeof(int), &failed);
  D->todo = oe_take((size_t)n, sizeof(int), &failed);
  D->slots = oe_take((size_t)n, sizeof(int), &failed);
  D->ev_n = oe_take((size_t)n, sizeof(int), &failed);
  D->ev_t = oe_take((size_t)n, sizeof(double), &failed);
  if (failed > 0.0) return oe_fail_memory(S, "the clusters of the local stepping", failed);
  if ((st = incidence(D)) != MARTELLO_OK) return st;
  for (int s = n - 1; s >= 0; s--) D->slots[D->nslots++] = s;
  if ((st = martello_model_initial_state(D->model, S->u, S->v)) != MARTELLO_OK)
    return fail(D, st, "local stepping: could not read the initial state");
  for (int i = 0; i < n; i++) {
    if (S->fixed[i]) S->v[i] = 0.0;
    D->u0[i] = S->u[i];
    D->ys[2 * i] = S->u[i];
    D->ys[2 * i + 1] = S->v[i];
    D->node_cl[i] = -1;
    D->mark[i] = S->fixed[i] ? -2 : 0;
  }
  if ((st = martello_observer_begin(S->obs, S->ev, S->u, S->v, "tighten rtol and atol")) != MARTELLO_OK)
    return st == MARTELLO_ERR_MEMORY ? st : fail(D, st, "local stepping: martello_observer_begin failed");
  if ((st = oe_commit(S, S->u, S->v)) != MARTELLO_OK) return fail(D, st, "local stepping: commit failed");
  if ((st = ode_problem_observe(&D->S, 0.0, D->ys, 0, 0)) != MARTELLO_OK) return st;
  /* the clusters at t = 0: the components of the groups and closed contacts */
  for (int i = 0; i < n; i++) {
    if (D->mark[i] != 0) continue;
    const int m = component(D, i, 0, -1);
    for (int k = 0; k < m; k++) D->mark[D->list[k]] = 2;   /* done */
    int *nodes = D->stack + n;
    memcpy(nodes, D->list, (size_t)m * sizeof(int));
    if ((st = start_cluster(D, nodes, m, 0.0, NULL)) != MARTELLO_OK) return st;
  }
  for (int i = 0; i < n; i++) D->mark[i] = S->fixed[i] ? -2 : -1;
  for (int s = 0; s < D->ncl; s++)
    if (D->cl[s]) reset_checked(D, s, 0.0);

  int k_out = 1;
  double t_out = oe_output_time(S, k_out);
  while (D->nheap > 0) {
    const int s = D->heap[0];
    const double tm = t_of(D->cl[s]);
    /* the rows every cluster's last step now holds */
    while (t_out <= tm && t_out < D->t_end) {
      if ((st = scene_sample(D, t_out, k_out * S->every, 1)) != MARTELLO_OK) return st;
      t_out = oe_output_time(S, ++k_out);
    }
    if (tm >= D->t_end) break;
    st = D->cl[s]->pend ? run_event(D, s) : step_cluster(D, s);
    if (st != MARTELLO_OK) return st;
  }
  /* t_end: every cluster's last step made final there; the last sample */
  for (int s = 0; s < D->ncl; s++) {
    cluster *c = D->cl[s];
    if (!c) continue;
    c->pend = PEND_NONE;
    if ((st = finalize(D, c, D->t_end, 0)) != MARTELLO_OK) return st;
    if ((st = ode_problem_flush_counts(&c->P)) != MARTELLO_OK) return st;
  }
  S->t_now = D->t_end;
  if ((st = scene_sample(D, D->t_end, k_out * S->every, 0)) != MARTELLO_OK) return st;
  return martello_observer_finish(S->obs, D->t_end);
}

int martello_ode_local_run(martello_model *model, martello_run *run) {
  driver d;
  driver *D = &d;
  memset(D, 0, sizeof *D);
  D->model = model;
  D->run = run;
  int st = ode_problem_setup(&D->S, model, run);
  if (st == MARTELLO_OK) {
    D->n = D->S.E.n;
    D->nc = D->S.E.nc;
    D->t_end = D->S.E.t_end;
    if (SUNContext_Create(NULL, &D->ctx) != 0) st = fail(D, MARTELLO_ERR_EXTERNAL, "SUNContext_Create failed");
  }
  if (st == MARTELLO_OK) st = integrate(D);
  for (int k = 0; k < D->ncl && D->cl; k++) free_cluster(D, k);
  if (D->ctx) SUNContext_Free(&D->ctx);
  void *arrays[] = {D->cl, D->heap, D->hkey, D->node_cl, D->node_loc, D->nd_first, D->nd_con, D->grp,
                    D->gr_first, D->gr_node, D->checked, D->u0, D->ys, D->mark, D->list, D->stack, D->todo, D->slots, D->ev_n, D->ev_t};
  for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++) free(arrays[k]);
  ode_problem_release(&D->S);
  return st;
}

