/* Dense LCPs of the event-driven integrator: Murty's least-index principal pivoting on an
 * SPD Delassus matrix, and the small Cholesky solves it and the persistent contacts use.
 * See c/event_driven_lcp.h. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "martello.h"
#include "event_driven_lcp.h"

struct martello_lcp {
  int max_m;
  double *sub;   /* principal submatrix W_aa, factored in place (max_m^2) */
  double *rhs;   /* its right-hand side (max_m) */
  int *in;       /* 1 if p_j is basic (w_j = 0) */
  int *idx;      /* indices of the basic set */
};

martello_lcp *martello_lcp_alloc(int max_m) {
  martello_lcp *l;
  size_t m = (size_t)(max_m > 0 ? max_m : 1);
  l = calloc(1, sizeof *l);
  if (l == NULL) return NULL;
  l->max_m = (int)m;
  l->sub = malloc(m * m * sizeof *l->sub);
  l->rhs = malloc(m * sizeof *l->rhs);
  l->in = malloc(m * sizeof *l->in);
  l->idx = malloc(m * sizeof *l->idx);
  if (l->sub == NULL || l->rhs == NULL || l->in == NULL || l->idx == NULL) {
    martello_lcp_free(&l);
    return NULL;
  }
  return l;
}

void martello_lcp_free(martello_lcp **lcp) {
  if (lcp == NULL || *lcp == NULL) return;
  free((*lcp)->sub);
  free((*lcp)->rhs);
  free((*lcp)->in);
  free((*lcp)->idx);
  free(*lcp);
  *lcp = NULL;
}

int martello_chol_factor(int m, double *A) {
  int i, j, k;
  double dmax = 0.0;
  for (i = 0; i < m; i++) dmax = fmax(dmax, fabs(A[i * m + i]));
  if (m == 1) return (A[0] > 0.0) ? MARTELLO_OK : MARTELLO_ERR_SINGULAR;
  for (j = 0; j < m; j++) {
    double d = A[j * m + j];
    for (k = 0; k < j; k++) d -= A[j * m + k] * A[j * m + k];
    /* a pivot at rounding level of the largest diagonal: W is singular (redundant
     * contacts, or a contact between two immovable sides) */
    if (!(d > 64.0 * DBL_EPSILON * m * dmax)) return MARTELLO_ERR_SINGULAR;
    d = sqrt(d);
    A[j * m + j] = d;
    for (i = j + 1; i < m; i++) {
      double s = A[i * m + j];
      for (k = 0; k < j; k++) s -= A[i * m + k] * A[j * m + k];
      A[i * m + j] = s / d;
    }
  }
  return MARTELLO_OK;
}

void martello_chol_solve(int m, const double *L, double *b) {
  int i, k;
  if (m == 1) {
    b[0] /= L[0];
    return;
  }
  for (i = 0; i < m; i++) {
    double s = b[i];
    for (k = 0; k < i; k++) s -= L[i * m + k] * b[k];
    b[i] = s / L[i * m + i];
  }
  for (i = m - 1; i >= 0; i--) {
    double s = b[i];
    for (k = i + 1; k < m; k++) s -= L[k * m + i] * b[k];
    b[i] = s / L[i * m + i];
  }
}

int martello_lcp_solve(martello_lcp *lcp, int m, const double *W, const double *q, double *p,
                       double *w, int *pivots) {
  int i, j, k, na, st, it;
  const int max_pivots = 50 * m + 50;
  if (lcp == NULL || m < 0 || m > lcp->max_m || W == NULL || q == NULL || p == NULL || w == NULL)
    return MARTELLO_ERR_ARGUMENT;
  if (pivots) *pivots = 0;
  if (m == 0) return MARTELLO_OK;
  /* start from the contacts that approach (q < 0): for a single contact, and for
   * contacts that do not interact, this is already the solution */
  for (j = 0; j < m; j++) lcp->in[j] = q[j] < 0.0;
  for (it = 0; it <= max_pivots; it++) {
    double pmax = 0.0;
    int flip = -1;
    na = 0;
    for (j = 0; j < m; j++)
      if (lcp->in[j]) lcp->idx[na++] = j;
    for (i = 0; i < na; i++) {
      for (k = 0; k < na; k++) lcp->sub[i * na + k] = W[lcp->idx[i] * m + lcp->idx[k]];
      lcp->rhs[i] = -q[lcp->idx[i]];
    }
    st = martello_chol_factor(na, lcp->sub);
    if (st != MARTELLO_OK) return st;
    martello_chol_solve(na, lcp->sub, lcp->rhs);
    for (j = 0; j < m; j++) p[j] = 0.0;
    for (i = 0; i < na; i++) p[lcp->idx[i]] = lcp->rhs[i];
    for (j = 0; j < m; j++) pmax = fmax(pmax, fabs(p[j]));
    /* w = W p + q; the violations are judged against the rounding of each term */
    for (j = 0; j < m && flip < 0; j++) {
      double s = q[j], mag = fabs(q[j]);
      for (k = 0; k < m; k++) {
        s += W[j * m + k] * p[k];
        mag += fabs(W[j * m + k] * p[k]);
      }
      w[j] = lcp->in[j] ? 0.0 : s;
      if (lcp->in[j] && p[j] < -64.0 * DBL_EPSILON * pmax) flip = j;
      if (!lcp->in[j] && s < -64.0 * DBL_EPSILON * mag) flip = j;
    }
    if (flip < 0) {
      for (j = 0; j < m; j++) {
        if (p[j] < 0.0) p[j] = 0.0;
        if (w[j] < 0.0) w[j] = 0.0;
      }
      return MARTELLO_OK;
    }
    lcp->in[flip] = !lcp->in[flip];
    if (pivots) (*pivots)++;
  }
  return MARTELLO_ERR_NOT_CONVERGED;
}
