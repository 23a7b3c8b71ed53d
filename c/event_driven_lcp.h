/* Small dense linear complementarity problems of the event-driven integrator
 * (c/event_driven.c, docs/event-driven.md): the impulse-level Newton impact law and the
 * acceleration-level contact law of persistent contacts, both of the form
 *     w = W p + q,   w >= 0,   p >= 0,   w^T p = 0
 * with W = G M^-1 G^T the Delassus matrix of the contacts involved (symmetric positive
 * definite when the contacts are independent). Matrices are row-major m x m. */
#ifndef MARTELLO_EVENT_DRIVEN_LCP_H
#define MARTELLO_EVENT_DRIVEN_LCP_H

typedef struct martello_lcp martello_lcp;

/* Workspace for problems of size up to max_m (allocated once, before the time loop). */
martello_lcp *martello_lcp_alloc(int max_m);
void martello_lcp_free(martello_lcp **lcp);

/* Murty's least-index principal pivoting (Murty 1974; finite for P-matrices, which an SPD
 * W is). On return p and w (length m) solve the LCP; *pivots counts the principal pivots.
 * Returns MARTELLO_OK, MARTELLO_ERR_SINGULAR (a principal submatrix of W is not positive
 * definite: redundant contacts), MARTELLO_ERR_NOT_CONVERGED (pivot limit) or
 * MARTELLO_ERR_ARGUMENT. */
int martello_lcp_solve(martello_lcp *lcp, int m, const double *W, const double *q, double *p,
                       double *w, int *pivots);

/* Cholesky factorization in place (lower triangle of the row-major m x m matrix A holds L)
 * and the solve L L^T x = b in place. factor returns MARTELLO_ERR_SINGULAR if A is not
 * numerically positive definite. m = 1 is a plain division (exact to one rounding). */
int martello_chol_factor(int m, double *A);
void martello_chol_solve(int m, const double *L, double *b);

#endif
