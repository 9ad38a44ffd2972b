/* The contact blocks of the ring's Jacobian added into its CSC values (ring_hb.py).
 *
 * Contact e has m local coordinates U = Q_e x_e on its d DOFs (Q_e: m x d, row-major)
 * and the local Jacobian dF_e (n_b m x n_b m, rows and columns c m + j: harmonic
 * coefficient c, coordinate j). Its block of the ring's Jacobian is
 * (I (x) Q_e)^T dF_e (I (x) Q_e), (n_b d x n_b d), rows and columns c d + a, each entry
 * added to data[pos], column by column, element after element. An element's entries
 * fall on distinct places, so the sums at each place run in element order: the order of
 * ring_hb.py's bincount (the same sums in the same sequence). Plain C99, no allocation.
 */
#include <stddef.h>

/* The loops of ring_add_blocks, inlined with m a constant where it is called with one
 * (the loops over j unrolled). */
static inline void add_blocks(int n_e, int nb, const int m, int d, const double *Q,
                              const double *dF, const int *pos, double *data, double *work)
{
    const int nm = nb * m, nd = nb * d;
    for (int e = 0; e < n_e; ++e) {
        const double *Qe = Q + (size_t)e * m * d, *F = dF + (size_t)e * nm * nm;
        const int *pe = pos + (size_t)e * nd * nd;
        /* T = dF_e (I (x) Q_e): T[r, c d + a] = sum_j F[r, c m + j] Q[j, a] */
        for (int r = 0; r < nm; ++r)
            for (int c = 0; c < nb; ++c)
                for (int a = 0; a < d; ++a) {
                    double s = 0.0;
                    for (int j = 0; j < m; ++j)
                        s += F[(size_t)r * nm + c * m + j] * Qe[j * d + a];
                    work[(size_t)r * nd + c * d + a] = s;
                }
        /* B = (I (x) Q_e)^T T, row by row over contiguous rows of T (vectorised): row
         * c d + a = sum_j Q[j, a] T[c m + j, :] */
        double *B = work + (size_t)nm * nd;
        for (int c = 0; c < nb; ++c)
            for (int a = 0; a < d; ++a) {
                double *row = B + (size_t)(c * d + a) * nd;
                for (int col = 0; col < nd; ++col)
                    row[col] = 0.0;
                for (int j = 0; j < m; ++j) {
                    const double q = Qe[j * d + a], *t = work + (size_t)(c * m + j) * nd;
                    for (int col = 0; col < nd; ++col)
                        row[col] += q * t[col];
                }
            }
        /* added column by column: the places of one CSC column are close together */
        for (int col = 0; col < nd; ++col)
            for (int r = 0; r < nd; ++r)
                data[*pe++] += B[(size_t)r * nd + col];
    }
}

/* data[pos[k]] += the k-th block entry, column-major per element (above); work:
 * (n_b m + n_b d) n_b d doubles. */
void ring_add_blocks(int n_e, int nb, int m, int d, const double *Q, const double *dF,
                     const int *pos, double *data, double *work)
{
    if (m == 2)   /* one tangent and the normal: the contacts of UPD-24 */
        add_blocks(n_e, nb, 2, d, Q, dF, pos, data, work);
    else
        add_blocks(n_e, nb, m, d, Q, dF, pos, data, work);
}
