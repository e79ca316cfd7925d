/*
 * Plain C reference loop of the GMS friction recursion, for benchmarks/bench_gms.py.
 *
 * The same forward-Euler recursion as greybox.models.friction.kernels.gms_friction_kernel
 * (see docs/friction-models.md): N Maxwell-slip elements sharing the Stribeck
 * curve s(v) = s_inf + (s_0 - s_inf) exp(-|v|/v_s), stick z += v T until the
 * deflection reaches alpha_i s(v) in the direction of motion, slip
 * z += T alpha_i C (sgn v - z / (alpha_i s)) until the velocity reverses or stops.
 *
 * Usage:
 *   gms_loop VELOCITY.bin FRICTION.bin REPEATS T C SIGMA S0 SINF VS MU N alpha_1..alpha_N k_1..k_N
 * VELOCITY.bin holds the velocity [mm/s] as native float64; FRICTION.bin receives
 * the friction of the last repeat. Prints the best time per step in ns.
 * Build: cc -O2 -o gms_loop gms_loop.c -lm
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define MAX_ELEMENTS 64

static void gms_friction(const double *velocity, long n, double T, int n_el, const double *alpha,
                         const double *k, double sigma, double s_0, double s_inf, double v_s,
                         double c, double mu, double *z, signed char *mode, double *friction)
{
    double damping[MAX_ELEMENTS];
    const double c_dt = c * T, s_drop = s_0 - s_inf, inv_v_s = 1.0 / v_s;
    for (int i = 0; i < n_el; i++)
        damping[i] = sigma * alpha[i];
    for (long j = 0; j < n; j++) {
        const double v = velocity[j];
        const double s = s_inf + s_drop * exp(-fabs(v) * inv_v_s);
        const double inv_s = 1.0 / s;
        const int d = v > 0.0 ? 1 : (v < 0.0 ? -1 : 0);
        const double fd = (double)d, v_dt = v * T;
        double f = mu * v;
        for (int i = 0; i < n_el; i++) {
            const double z_old = z[i], s_i = alpha[i] * s;
            int m = mode[i];
            double z_new;
            if (m != 0 && m != d)
                m = 0;
            if (m == 0) {
                z_new = z_old + v_dt;
                if (d != 0 && fd * z_new >= s_i) {
                    m = d;
                    if (fd * z_old < s_i)
                        z_new = fd * s_i;
                    else
                        z_new = z_old + c_dt * (alpha[i] * fd - z_old * inv_s);
                }
            } else {
                z_new = z_old + c_dt * (alpha[i] * fd - z_old * inv_s);
            }
            f += k[i] * z_old + damping[i] * ((z_new - z_old) / T);
            z[i] = z_new;
            mode[i] = (signed char)m;
        }
        friction[j] = f;
    }
}

int main(int argc, char **argv)
{
    if (argc < 12) {
        fprintf(stderr, "usage: %s VELOCITY.bin FRICTION.bin REPEATS T C SIGMA S0 SINF VS MU N alpha.. k..\n", argv[0]);
        return 2;
    }
    const int repeats = atoi(argv[3]);
    const double T = atof(argv[4]), c = atof(argv[5]), sigma = atof(argv[6]), s_0 = atof(argv[7]);
    const double s_inf = atof(argv[8]), v_s = atof(argv[9]), mu = atof(argv[10]);
    const int n_el = atoi(argv[11]);
    if (n_el < 1 || n_el > MAX_ELEMENTS || argc != 12 + 2 * n_el) {
        fprintf(stderr, "expected N alphas and N stiffnesses after N\n");
        return 2;
    }
    double alpha[MAX_ELEMENTS], k[MAX_ELEMENTS], z[MAX_ELEMENTS];
    signed char mode[MAX_ELEMENTS];
    for (int i = 0; i < n_el; i++) {
        alpha[i] = atof(argv[12 + i]);
        k[i] = atof(argv[12 + n_el + i]);
    }

    FILE *in = fopen(argv[1], "rb");
    if (!in) {
        perror(argv[1]);
        return 1;
    }
    fseek(in, 0, SEEK_END);
    const long n = ftell(in) / (long)sizeof(double);
    fseek(in, 0, SEEK_SET);
    double *velocity = malloc(n * sizeof(double)), *friction = malloc(n * sizeof(double));
    if (!velocity || !friction || fread(velocity, sizeof(double), n, in) != (size_t)n) {
        fprintf(stderr, "cannot read %s\n", argv[1]);
        return 1;
    }
    fclose(in);

    double best = INFINITY;
    for (int r = 0; r < repeats; r++) {
        for (int i = 0; i < n_el; i++) {
            z[i] = 0.0;
            mode[i] = 0;
        }
        struct timespec t0, t1;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        gms_friction(velocity, n, T, n_el, alpha, k, sigma, s_0, s_inf, v_s, c, mu, z, mode, friction);
        clock_gettime(CLOCK_MONOTONIC, &t1);
        const double ns = (t1.tv_sec - t0.tv_sec) * 1e9 + (t1.tv_nsec - t0.tv_nsec);
        if (ns < best)
            best = ns;
    }

    FILE *out = fopen(argv[2], "wb");
    if (!out || fwrite(friction, sizeof(double), n, out) != (size_t)n) {
        perror(argv[2]);
        return 1;
    }
    fclose(out);
    printf("%.6f\n", best / (double)n);
    free(velocity);
    free(friction);
    return 0;
}
