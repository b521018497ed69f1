/* Benchmark-only C reference of the Strang Lie-Poisson step of the free rigid body.
 *
 * Same mathematics as dirac.rigidbody.splitting (method lie-poisson-2): the 3-term split
 * H = M1^2/(2 I1) + M2^2/(2 I2) + M3^2/(2 I3) of (247); the exact flow of H_k turns M
 * about body axis e_k by -theta and R on the right by +theta, theta = h M_k / I_k
 * (Euler-Poisson equations (250)-(251)). Strang step H1(h/2) H2(h/2) H3(h) H2(h/2) H1(h/2),
 * the last half-step of H1 merged with the first of the next step: 4 rotations per step.
 *
 * Compiled by `dirac bench` with `cc -O3 -shared -fPIC` into a temporary directory and
 * called through ctypes; it is the physical-limit anchor of the kernel timing, never
 * used for results.
 */
#include <math.h>

static inline void turn(double *M, double *R, int k, double h, int with_R)
{
    int j = (k + 1) % 3, l = (k + 2) % 3;
    double theta = h * M[k];
    double c = cos(theta), s = sin(theta);
    double mj = M[j], ml = M[l];
    M[j] = c * mj + s * ml;
    M[l] = c * ml - s * mj;
    if (with_R) {
        for (int row = 0; row < 3; ++row) {
            double a = R[3 * row + j], b = R[3 * row + l];
            R[3 * row + j] = c * a + s * b;
            R[3 * row + l] = c * b - s * a;
        }
    }
}

/* Advance M (3) and R (3x3, row-major) in place by n_steps Strang steps of size dt.
 * inv = (1/I1, 1/I2, 1/I3). */
void strang_advance(double *M, double *R, const double *inv, double dt, long n_steps, int with_R)
{
    if (n_steps <= 0)
        return;
    double h1_half = 0.5 * dt * inv[0], h1_join = dt * inv[0];
    double h2_half = 0.5 * dt * inv[1], h3 = dt * inv[2];
    turn(M, R, 0, h1_half, with_R);
    for (long step = 0; step < n_steps; ++step) {
        turn(M, R, 1, h2_half, with_R);
        turn(M, R, 2, h3, with_R);
        turn(M, R, 1, h2_half, with_R);
        turn(M, R, 0, step < n_steps - 1 ? h1_join : h1_half, with_R);
    }
}
