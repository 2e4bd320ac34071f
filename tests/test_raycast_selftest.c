/* Self-test of tests/shapes.h and tests/raycast.h against ANALYTIC results.
 *
 *   gcc -std=c99 -O2 -Wall -Wextra -pedantic -Werror -Itests tests/test_raycast_selftest.c -lm
 *   g++ -std=c++11 -x c++ ... (same flags)
 *
 * Tolerances (see the individual sections):
 *   - mesh volumes: box exact (1e-12 rel); UV sphere and torus against the exact volume of
 *     their polyhedra (closed-form wedge formula, 1e-5 rel, float vertex rounding), plus the
 *     smooth-solid volume within the tessellation bound; torus knot within 1.5% of
 *     pi*a^2*L*(polygon area factor).
 *   - sphere thickness: rigorous bounds: the tessellated UV sphere is a convex polyhedron
 *     between the ball of radius r_in (min face-plane distance) and the ball of radius r,
 *     so chord(r_in) - 1e-6 <= thickness <= chord(r) + 1e-6 (1e-6 covers float vertices).
 *   - box, box with camera inside, box + occluder, overlapping boxes, torus in its ring
 *     plane (exact polygon cross-section): 1e-10 absolute (machine precision territory;
 *     the observed error is printed).
 *   - torus off the ring plane vs the smooth torus: 3e-3 absolute (tessellation, 256x128).
 *   - exact ties: rays bit-exactly through vertices/edges (sphere pole fans, box edges and
 *     corners, a fold vertex with a mixed front/back fan): 1e-14 / 1e-12 absolute.
 *   - winding invariants: exact vertex rays along the axes through every vertex and 20000
 *     random rays per mesh: winding stays in {0,1} and returns to 0.
 *   - camera: clip.w of proj*view (float matrices) equals t within 1e-5 relative, ndc within 1e-5.
 */
#include <stdarg.h>
#include <stdio.h>
#include <time.h>

#include "raycast.h"
#include "shapes.h"

static int g_pass, g_fail;

static void check(int ok, const char *fmt, ...) {
  if (ok) {
    g_pass++;
    return;
  }
  g_fail++;
  {
    va_list ap;
    va_start(ap, fmt);
    printf("FAIL: ");
    vprintf(fmt, ap);
    printf("\n");
    va_end(ap);
  }
}

#define PI 3.14159265358979323846

/* ------------------------------------------------------------------ mesh checks */

static int cmp_u64(const void *a, const void *b) {
  unsigned long long x = *(const unsigned long long *)a, y = *(const unsigned long long *)b;
  return x < y ? -1 : x > y ? 1 : 0;
}

/* closed, manifold (edges and vertex links), consistently oriented, non-degenerate.
   Returns 1 if ok, else 0 and a reason. Also reports the Euler characteristic. */
static int mesh_closed(const shp_mesh *m, int *euler, char *why, size_t nwhy) {
  int nt = m->icount / 3, i, k, ok = 0;
  unsigned long long *e = NULL, vc = (unsigned long long)m->vcount;
  int *deg = NULL, *start = NULL, *from = NULL, *to = NULL, *fill = NULL;
  double scale = 0;
  why[0] = 0;
  if (!m->pos || !m->idx || m->icount % 3 != 0 || nt == 0) {
    snprintf(why, nwhy, "empty or icount %% 3 != 0");
    return 0;
  }
  for (i = 0; i < m->icount; i++)
    if (m->idx[i] >= (unsigned)m->vcount) {
      snprintf(why, nwhy, "index out of range");
      return 0;
    }
  for (i = 0; i < 3 * m->vcount; i++)
    if (fabs(m->pos[i]) > scale) scale = fabs(m->pos[i]);
  for (i = 0; i < nt; i++) {
    const unsigned *t = m->idx + 3 * i;
    double a[3], b[3], c[3];
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      snprintf(why, nwhy, "triangle %d repeats a vertex", i);
      return 0;
    }
    for (k = 0; k < 3; k++) {
      a[k] = (double)m->pos[3 * t[1] + k] - m->pos[3 * t[0] + k];
      b[k] = (double)m->pos[3 * t[2] + k] - m->pos[3 * t[0] + k];
    }
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
    if (sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) <= 1e-12 * scale * scale) {
      snprintf(why, nwhy, "triangle %d degenerate", i);
      return 0;
    }
  }
  e = (unsigned long long *)malloc((size_t)m->icount * sizeof *e);
  deg = (int *)calloc((size_t)m->vcount + 1, sizeof(int));
  start = (int *)calloc((size_t)m->vcount + 1, sizeof(int));
  fill = (int *)calloc((size_t)m->vcount + 1, sizeof(int));
  from = (int *)malloc((size_t)m->icount * sizeof(int));
  to = (int *)malloc((size_t)m->icount * sizeof(int));
  if (!e || !deg || !start || !fill || !from || !to) {
    snprintf(why, nwhy, "out of memory");
    goto done;
  }
  for (i = 0; i < nt; i++)
    for (k = 0; k < 3; k++) e[3 * i + k] = m->idx[3 * i + k] * vc + m->idx[3 * i + (k + 1) % 3];
  qsort(e, (size_t)m->icount, sizeof *e, cmp_u64);
  for (i = 0; i < m->icount; i++) {
    unsigned long long a = e[i] / vc, b = e[i] % vc, rev = b * vc + a;
    if (i > 0 && e[i] == e[i - 1]) {
      snprintf(why, nwhy, "directed edge %llu->%llu used twice (inconsistent orientation or non-manifold)", a, b);
      goto done;
    }
    if (!bsearch(&rev, e, (size_t)m->icount, sizeof *e, cmp_u64)) {
      snprintf(why, nwhy, "edge %llu->%llu has no opposite half-edge (boundary or flipped)", a, b);
      goto done;
    }
  }
  /* vertex links: around every vertex the incident triangles form one cycle */
  for (i = 0; i < m->icount; i++) deg[m->idx[i]]++;
  for (i = 0; i < m->vcount; i++) {
    if (deg[i] == 0) {
      snprintf(why, nwhy, "vertex %d unused", i);
      goto done;
    }
    start[i + 1] = start[i] + deg[i];
  }
  for (i = 0; i < nt; i++)
    for (k = 0; k < 3; k++) {
      int v = (int)m->idx[3 * i + k], s = start[v] + fill[v]++;
      from[s] = (int)m->idx[3 * i + (k + 1) % 3];
      to[s] = (int)m->idx[3 * i + (k + 2) % 3];
    }
  for (i = 0; i < m->vcount; i++) {
    int n = deg[i], cur = to[start[i]], steps = 1, j;
    while (cur != from[start[i]] && steps <= n) {
      for (j = 0; j < n && from[start[i] + j] != cur; j++) {
      }
      if (j == n) break;
      cur = to[start[i] + j];
      steps++;
    }
    if (cur != from[start[i]] || steps != n) {
      snprintf(why, nwhy, "vertex %d: link is not a single cycle (non-manifold vertex)", i);
      goto done;
    }
  }
  *euler = m->vcount - m->icount / 2 + nt; /* E = 3F/2 for a closed mesh */
  ok = 1;
done:
  free(e);
  free(deg);
  free(start);
  free(fill);
  free(from);
  free(to);
  return ok;
}

static double mesh_volume(const shp_mesh *m) {
  double v = 0;
  int i;
  for (i = 0; i < m->icount; i += 3) {
    const float *a = m->pos + 3 * m->idx[i], *b = m->pos + 3 * m->idx[i + 1], *c = m->pos + 3 * m->idx[i + 2];
    v += (double)a[0] * ((double)b[1] * c[2] - (double)b[2] * c[1]) +
         (double)a[1] * ((double)b[2] * c[0] - (double)b[0] * c[2]) +
         (double)a[2] * ((double)b[0] * c[1] - (double)b[1] * c[0]);
  }
  return v / 6.0;
}

/* min distance from the origin to the planes of the faces (sphere inner radius) */
static double mesh_min_plane_dist(const shp_mesh *m) {
  double best = INFINITY;
  int i, k;
  for (i = 0; i < m->icount; i += 3) {
    const float *a = m->pos + 3 * m->idx[i], *b = m->pos + 3 * m->idx[i + 1], *c = m->pos + 3 * m->idx[i + 2];
    double e1[3], e2[3], n[3], l, d;
    for (k = 0; k < 3; k++) {
      e1[k] = (double)b[k] - a[k];
      e2[k] = (double)c[k] - a[k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    d = (n[0] * a[0] + n[1] * a[1] + n[2] * a[2]) / l;
    if (d < best) best = d;
  }
  return best;
}

/* Exact volume of a polyhedral solid of revolution: profile polygon (rho_k, z_k) in the
   half plane rho >= 0 swept over n equal wedges with planar faces. Each wedge of angle D is
   {(rho cos(D/2), s, z): (rho,z) in P, |s| <= rho sin(D/2)}, volume sin(D) * int_P rho dA. */
static double revolved_polygon_volume(const double *rho, const double *z, int npts, int n) {
  double m1 = 0;
  int i;
  for (i = 0; i < npts; i++) {
    int j = (i + 1) % npts;
    m1 += (rho[i] + rho[j]) * (rho[i] * z[j] - rho[j] * z[i]);
  }
  return n * sin(2.0 * PI / n) * fabs(m1) / 6.0;
}

static void test_meshes(void) {
  char why[256];
  int eu, ok, s, i, k;
  static const int sph[][2] = {{3, 2}, {4, 3}, {7, 5}, {32, 16}, {128, 64}};
  printf("-- meshes\n");
  for (s = 0; s < (int)(sizeof sph / sizeof sph[0]); s++) {
    float r = 1.25f;
    shp_mesh m = shp_sphere(r, sph[s][0], sph[s][1]);
    double rho[1024], z[1024], vex, v, rin;
    int st = sph[s][1];
    ok = mesh_closed(&m, &eu, why, sizeof why);
    check(ok, "sphere %dx%d not a closed oriented manifold: %s", sph[s][0], st, why);
    check(eu == 2, "sphere %dx%d Euler characteristic %d != 2", sph[s][0], st, eu);
    check(m.icount / 3 == 2 * sph[s][0] * (st - 1), "sphere triangle count");
    for (k = 0; k <= st; k++) {
      rho[k] = r * sin(PI * k / st);
      z[k] = r * cos(PI * k / st);
    }
    rho[0] = rho[st] = 0;
    vex = revolved_polygon_volume(rho, z, st + 1, sph[s][0]);
    v = mesh_volume(&m);
    rin = mesh_min_plane_dist(&m);
    check(fabs(v - vex) <= 1e-5 * vex, "sphere %dx%d volume %.9g != polyhedron %.9g", sph[s][0], st, v, vex);
    check(v > 0 && v <= 4.0 / 3.0 * PI * r * r * r * (1 + 1e-6) && v >= 4.0 / 3.0 * PI * rin * rin * rin * (1 - 1e-6),
          "sphere %dx%d volume %.9g outside [4/3 pi r_in^3, 4/3 pi r^3]", sph[s][0], st, v);
    if (sph[s][0] == 128)
      printf("   sphere 128x64 r=1.25: volume %.8f, polyhedron %.8f, 4/3 pi r^3 = %.8f (rel %.2e), r_in %.6f\n", v,
             vex, 4.0 / 3.0 * PI * r * r * r, 1 - v / (4.0 / 3.0 * PI * r * r * r), rin);
    shp_free(&m);
  }
  {
    shp_mesh m = shp_box(1.0f, 0.5f, 0.75f);
    double v;
    ok = mesh_closed(&m, &eu, why, sizeof why);
    check(ok, "box not a closed oriented manifold: %s", why);
    check(eu == 2 && m.vcount == 8 && m.icount == 36, "box counts/Euler");
    v = mesh_volume(&m);
    check(fabs(v - 3.0) <= 1e-12, "box volume %.17g != 8*hx*hy*hz = 3", v);
    printf("   box 2x1x1.5: volume %.17g (exact 3)\n", v);
    shp_free(&m);
  }
  {
    static const int tor[][2] = {{3, 3}, {5, 4}, {64, 32}, {256, 128}};
    for (s = 0; s < 4; s++) {
      float R = 2.0f, r = 0.5f;
      int nu = tor[s][0], nv = tor[s][1];
      shp_mesh m = shp_torus(R, r, nu, nv);
      double v, vex;
      ok = mesh_closed(&m, &eu, why, sizeof why);
      check(ok, "torus %dx%d not a closed oriented manifold: %s", nu, nv, why);
      check(eu == 0, "torus Euler characteristic %d != 0", eu);
      v = mesh_volume(&m);
      /* exact polyhedron: wedge formula with a regular nv-gon profile centred at R */
      vex = nu * sin(2 * PI / nu) * R * (nv / 2.0) * r * r * sin(2 * PI / nv);
      check(fabs(v - vex) <= 1e-5 * vex, "torus %dx%d volume %.9g != polyhedron %.9g", nu, nv, v, vex);
      if (nu >= 64) {
        double va = 2 * PI * PI * R * r * r, tol = 1.0 - (nu * sin(2 * PI / nu) / (2 * PI)) * (nv * sin(2 * PI / nv) / (2 * PI));
        check(fabs(v - va) <= 1.01 * tol * va, "torus %dx%d volume %.9g vs 2 pi^2 R r^2 = %.9g beyond %.2e", nu, nv, v,
              va, tol);
        printf("   torus %dx%d R=2 r=0.5: volume %.8f, polyhedron %.8f, 2pi^2Rr^2 = %.8f (rel %.2e, bound %.2e)\n", nu, nv,
               v, vex, va, 1 - v / va, tol);
      }
      shp_free(&m);
    }
  }
  {
    /* torus knots: topology, volume ~ pi a^2 L, no twist seam, clearance */
    static const struct {
      int p, q;
      float R, r, a;
      int seg, sides;
    } kn[] = {{2, 3, 1.0f, 0.4f, 0.12f, 256, 16}, {3, 2, 1.0f, 0.4f, 0.1f, 300, 12}, {3, 5, 1.0f, 0.35f, 0.07f, 400, 10}};
    for (s = 0; s < 3; s++) {
      shp_mesh m = shp_torus_knot(kn[s].p, kn[s].q, kn[s].R, kn[s].r, kn[s].a, kn[s].seg, kn[s].sides);
      double v, L = 0, vex, ratio_min = 1e9, ratio_max = 0, clear = 1e9;
      int N = 20000, sides = kn[s].sides, seg = kn[s].seg;
      ok = mesh_closed(&m, &eu, why, sizeof why);
      check(ok, "torus knot (%d,%d) not a closed oriented manifold: %s", kn[s].p, kn[s].q, why);
      check(eu == 0, "torus knot Euler characteristic %d != 0", eu);
      for (i = 0; i < N; i++) {
        double c[3], d[3];
        shp__knot_curve(kn[s].p, kn[s].q, kn[s].R, kn[s].r, 2 * PI * (i + 0.5) / N, c, d);
        L += sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) * 2 * PI / N;
      }
      v = mesh_volume(&m);
      vex = PI * kn[s].a * kn[s].a * L * (sides * sin(2 * PI / sides) / (2 * PI));
      check(v > 0 && fabs(v - vex) <= 0.015 * vex, "torus knot (%d,%d) volume %.6g vs %.6g", kn[s].p, kn[s].q, v, vex);
      /* seam: longitudinal edge lengths across the seam match those of the next ring */
      for (k = 0; k < sides; k++) {
        const float *a0 = m.pos + 3 * ((seg - 1) * sides + k), *b0 = m.pos + 3 * k, *c0 = m.pos + 3 * (sides + k);
        double l1 = 0, l2 = 0, t;
        for (i = 0; i < 3; i++) {
          t = (double)a0[i] - b0[i];
          l1 += t * t;
          t = (double)c0[i] - b0[i];
          l2 += t * t;
        }
        t = sqrt(l1 / l2);
        if (t < ratio_min) ratio_min = t;
        if (t > ratio_max) ratio_max = t;
      }
      check(ratio_min > 0.9 && ratio_max < 1.1, "torus knot (%d,%d) twist seam: edge ratio %.3f..%.3f", kn[s].p, kn[s].q,
            ratio_min, ratio_max);
      /* centre-line clearance between non-neighbouring parts > 2a */
      {
        int M = 600, a, b;
        double (*cp)[3] = (double (*)[3])malloc(sizeof(double[3]) * (size_t)M), dd[3];
        if (cp) {
          for (a = 0; a < M; a++) shp__knot_curve(kn[s].p, kn[s].q, kn[s].R, kn[s].r, 2 * PI * a / M, cp[a], dd);
          for (a = 0; a < M; a++)
            for (b = a + 1; b < M; b++) {
              double arc = (double)(b - a) / M * L, dist2;
              if (arc > L / 2) arc = L - arc;
              if (arc < 4 * kn[s].a) continue;
              dist2 = (cp[a][0] - cp[b][0]) * (cp[a][0] - cp[b][0]) + (cp[a][1] - cp[b][1]) * (cp[a][1] - cp[b][1]) +
                      (cp[a][2] - cp[b][2]) * (cp[a][2] - cp[b][2]);
              if (sqrt(dist2) < clear) clear = sqrt(dist2);
            }
          free(cp);
        }
      }
      check(clear > 2.2 * kn[s].a, "torus knot (%d,%d) strands too close: %.4f vs tube %.3f", kn[s].p, kn[s].q, clear,
            kn[s].a);
      printf("   torus knot (%d,%d) %dx%d: volume %.6f vs pi a^2 L*area %.6f (rel %.2e), seam ratio %.3f..%.3f, "
             "clearance %.3f (2a = %.3f)\n",
             kn[s].p, kn[s].q, seg, sides, v, vex, v / vex - 1, ratio_min, ratio_max, clear, 2 * kn[s].a);
      shp_free(&m);
    }
  }
  {
    shp_mesh m = shp_grid_plane(2.0f, 1.0f, 3);
    double nz = 0;
    for (i = 0; i < m.icount; i += 3) {
      const float *a = m.pos + 3 * m.idx[i], *b = m.pos + 3 * m.idx[i + 1], *c = m.pos + 3 * m.idx[i + 2];
      nz += ((double)b[0] - a[0]) * ((double)c[1] - a[1]) - ((double)b[1] - a[1]) * ((double)c[0] - a[0]);
    }
    check(m.vcount == 16 && m.icount == 54 && fabs(nz - 2 * 4 * 2.0) < 1e-9, "grid plane counts / +z normal (%g)", nz);
    shp_free(&m);
  }
  {
    shp_mesh m = shp_sphere(1, 2, 2), b = shp_box(1, 1, 1), c;
    check(m.vcount == 0 && m.pos == NULL && m.idx == NULL, "invalid sphere params -> zeroed mesh");
    float t[16];
    c = shp_box(1, 1, 1);
    shp_mat_translate(t, 0.5f, 0, 0);
    shp_transform(&c, t);
    check(c.pos[0] == -0.5f && c.pos[3] == 1.5f, "shp_transform translate");
    check(shp_append(&b, &c) && b.vcount == 16 && b.icount == 72, "shp_append");
    shp_free(&b);
    shp_free(&c);
    shp_free(&m);
  }
}

/* ------------------------------------------------------------------ raycast helpers */

static rc_camera make_cam(double ex, double ey, double ez, double tx, double ty, double tz, double ux, double uy,
                          double uz, double fovy, int w, int h, double zn, double zf) {
  rc_camera c;
  memset(&c, 0, sizeof c);
  c.eye[0] = ex;
  c.eye[1] = ey;
  c.eye[2] = ez;
  c.target[0] = tx;
  c.target[1] = ty;
  c.target[2] = tz;
  c.up[0] = ux;
  c.up[1] = uy;
  c.up[2] = uz;
  c.fovy_deg = fovy;
  c.width = w;
  c.height = h;
  c.aspect = (double)w / h;
  c.znear = zn;
  c.zfar = zf;
  return c;
}

static rc_object make_obj(const shp_mesh *m, const float model[16], int sign) {
  rc_object o;
  memset(&o, 0, sizeof o);
  o.pos = m->pos;
  o.vcount = m->vcount;
  o.idx = m->idx;
  o.icount = m->icount;
  if (model)
    memcpy(o.model, model, sizeof o.model);
  else
    shp_mat_identity(o.model);
  o.sign = sign;
  return o;
}

/* analytic line/sphere: t0 <= t1 or 0 if missed */
static int ray_sphere(const double o[3], const double d[3], const double c[3], double r, double *t0, double *t1) {
  double oc[3] = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
  double a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
  double cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - r * r, disc = b * b - a * cc, s;
  if (disc <= 0) return 0;
  s = sqrt(disc);
  *t0 = (-b - s) / a;
  *t1 = (-b + s) / a;
  return 1;
}

/* analytic line/axis-aligned box (slabs) */
static int ray_box(const double o[3], const double d[3], const double lo[3], const double hi[3], double *t0, double *t1) {
  double a = -INFINITY, b = INFINITY;
  int k;
  for (k = 0; k < 3; k++) {
    if (d[k] == 0) {
      if (o[k] < lo[k] || o[k] > hi[k]) return 0;
    } else {
      double u = (lo[k] - o[k]) / d[k], v = (hi[k] - o[k]) / d[k];
      if (u > v) {
        double t = u;
        u = v;
        v = t;
      }
      if (u > a) a = u;
      if (v < b) b = v;
    }
  }
  if (a >= b) return 0;
  *t0 = a;
  *t1 = b;
  return 1;
}

/* length of [t0,t1] inside [a,b] */
static double seg(double t0, double t1, double a, double b) {
  double lo = t0 > a ? t0 : a, hi = t1 < b ? t1 : b;
  return hi > lo ? hi - lo : 0.0;
}

/* ------------------------------------------------------------------ camera */

static void test_camera(void) {
  rc_camera c = make_cam(1.5, -2.0, 4.0, 0.2, 0.3, -0.5, 0.1, 1.0, 0.2, 55.0, 200, 120, 0.25, 50.0);
  float V[16], P[16];
  double worst = 0;
  int i, j, k, r;
  static const double sp[][2] = {{100, 60}, {0, 0}, {200, 120}, {17.5, 99.25}, {150.5, 3.5}};
  printf("-- camera matrices vs rays\n");
  rc_camera_matrices(&c, V, P);
  for (i = 0; i < 5; i++) {
    double o[3], d[3], x = sp[i][0] / c.width * 2 - 1, y = sp[i][1] / c.height * 2 - 1;
    static const double ts[] = {0.25, 3.7, 50.0};
    rc_camera_ray(&c, sp[i][0], sp[i][1], o, d);
    for (j = 0; j < 3; j++) {
      double p[4], e[4], cl[4], t = ts[j];
      for (k = 0; k < 3; k++) p[k] = o[k] + t * d[k];
      p[3] = 1;
      for (r = 0; r < 4; r++) e[r] = V[r] * p[0] + V[4 + r] * p[1] + V[8 + r] * p[2] + V[12 + r] * p[3];
      for (r = 0; r < 4; r++) cl[r] = P[r] * e[0] + P[4 + r] * e[1] + P[8 + r] * e[2] + P[12 + r] * e[3];
      check(fabs(e[2] + t) <= 1e-5 * t, "view z %.9g != -t %.9g", e[2], -t);
      check(fabs(cl[3] - t) <= 1e-5 * t, "clip w %.9g != t %.9g", cl[3], t);
      check(fabs(cl[0] / cl[3] - x) <= 1e-5 && fabs(cl[1] / cl[3] - y) <= 1e-5, "ndc (%.7f,%.7f) != (%.7f,%.7f)",
            cl[0] / cl[3], cl[1] / cl[3], x, y);
      if (j == 0) check(fabs(cl[2] / cl[3] + 1) <= 1e-4, "ndc z at znear %.7f != -1", cl[2] / cl[3]);
      if (j == 2) check(fabs(cl[2] / cl[3] - 1) <= 1e-4, "ndc z at zfar %.7f != 1", cl[2] / cl[3]);
      if (fabs(cl[3] - t) / t > worst) worst = fabs(cl[3] - t) / t;
    }
  }
  printf("   max rel |clip.w - t| = %.2e (float matrices)\n", worst);
}

/* ------------------------------------------------------------------ sphere */

static void test_sphere(void) {
  shp_mesh m = shp_sphere(1.0f, 128, 64);
  float model[16];
  double cen[3] = {0.3, -0.2, 0.1}, rin = mesh_min_plane_dist(&m), rout = 1.0 + 1e-6, tol = 1e-6;
  double worst = 0, worst_in = 0;
  rc_object o;
  rc_scene sc;
  int px, py, nhit = 0, nmiss = 0, ninside = 0, nint = 0, nint_ok = 0, nedge = 0, nedge_ok = 0;
  printf("-- sphere 128x64 r=1 (r_in = %.6f), bounds chord(r_in)-%.0e <= th <= chord(r)+%.0e\n", rin, tol, tol);
  shp_mat_translate(model, 0.3f, -0.2f, 0.1f);
  o = make_obj(&m, model, +1);
  check(rc_scene_init(&sc, &o, 1), "rc_scene_init sphere");
  {
    rc_camera c = make_cam(0.5, 1.0, 3.5, 0, 0, 0, 0, 1, 0, 40.0, 192, 128, 0.1, 100.0);
    for (py = 0; py < c.height; py += 3)
      for (px = 0; px < c.width; px += 3) {
        double o3[3], d[3], a0, a1, b0, b1, lo, hi;
        rc_result r = rc_trace(&sc, &c, px + 0.5, py + 0.5);
        int hout, hin;
        rc_camera_ray(&c, px + 0.5, py + 0.5, o3, d);
        hout = ray_sphere(o3, d, cen, rout, &a0, &a1);
        hin = ray_sphere(o3, d, cen, rin, &b0, &b1);
        if (!hout) {
          nmiss++;
          check(r.thickness == 0 && r.faces_front == 0 && r.faces_back == 0, "sphere miss px %d,%d th %.3g", px, py,
                r.thickness);
          continue;
        }
        nhit++;
        hi = seg(a0, a1, c.znear, c.zfar) + tol;
        lo = hin ? seg(b0, b1, c.znear, c.zfar) - tol : 0.0;
        check(r.thickness >= lo && r.thickness <= hi, "sphere px %d,%d th %.9f not in [%.9f, %.9f]", px, py,
              r.thickness, lo, hi);
        if (hin) {
          double e = fabs(r.thickness - (a1 - a0));
          ninside++;
          if (e > worst) worst = e;
          check(r.faces_front == 1 && r.faces_back == 1, "sphere px %d,%d faces %d/%d", px, py, r.faces_front,
                r.faces_back);
        }
      }
    /* rc_interior consistency with the analytic silhouette */
    for (py = 1; py < c.height - 1; py += 2)
      for (px = 1; px < c.width - 1; px += 2) {
        static const double off[13][2] = {{0.5, 0.5}, {0, 0},     {1, 0},      {0, 1},     {1, 1},
                                          {-0.5, -0.5}, {0.5, -0.5}, {1.5, -0.5}, {-0.5, 0.5}, {1.5, 0.5},
                                          {-0.5, 1.5}, {0.5, 1.5},  {1.5, 1.5}};
        int k, allin = 1, allout = 1, cin, cout, mixed = 0, ri;
        for (k = 0; k < 13; k++) {
          double o3[3], d[3], t0, t1;
          rc_camera_ray(&c, px + off[k][0], py + off[k][1], o3, d);
          cin = ray_sphere(o3, d, cen, rin, &t0, &t1);
          cout = !ray_sphere(o3, d, cen, rout, &t0, &t1);
          if (!cin) allin = 0;
          if (!cout) allout = 0;
          if (k > 0 && ((cin && mixed == 2) || (cout && mixed == 1))) mixed = 3;
          if (k == 0) mixed = cin ? 1 : cout ? 2 : 0;
        }
        if (!allin && !allout && mixed != 3) continue; /* inside the tessellation band: undecided */
        ri = rc_interior(&sc, &c, px, py);
        if (allin || allout) {
          nint++;
          nint_ok += ri == 1;
        } else {
          nedge++;
          nedge_ok += ri == 0;
        }
      }
    check(nint_ok == nint, "rc_interior: %d of %d clearly interior pixels flagged interior", nint_ok, nint);
    check(nedge_ok == nedge && nedge > 50, "rc_interior: %d of %d silhouette pixels flagged non-interior", nedge_ok,
          nedge);
    printf("   outside view: %d hit, %d missed, %d fully inside r_in: max |th - exact chord(r=1)| = %.3e\n", nhit,
           nmiss, ninside, worst);
    printf("   rc_interior: %d/%d clearly-inside/outside pixels interior, %d/%d silhouette pixels not interior\n",
           nint_ok, nint, nedge_ok, nedge);
  }
  {
    /* camera inside the sphere: thickness = t_exit - znear */
    rc_camera c = make_cam(0.5, -0.1, 0.3, 0, 0, -5, 0, 1, 0, 70.0, 64, 48, 0.05, 100.0);
    for (py = 0; py < c.height; py += 2)
      for (px = 0; px < c.width; px += 2) {
        double o3[3], d[3], a0, a1, b0, b1;
        rc_result r = rc_trace(&sc, &c, px + 0.5, py + 0.5);
        rc_camera_ray(&c, px + 0.5, py + 0.5, o3, d);
        ray_sphere(o3, d, cen, rout, &a0, &a1);
        ray_sphere(o3, d, cen, rin, &b0, &b1);
        check(r.thickness >= b1 - c.znear - tol && r.thickness <= a1 - c.znear + tol,
              "inside sphere px %d,%d th %.9f not in [%.9f, %.9f]", px, py, r.thickness, b1 - c.znear, a1 - c.znear);
        check(r.faces_front == 0 && r.faces_back == 1, "inside sphere faces %d/%d", r.faces_front, r.faces_back);
        if (fabs(r.thickness - (a1 - c.znear)) > worst_in) worst_in = fabs(r.thickness - (a1 - c.znear));
      }
    printf("   camera inside: max |th - (t_exit - znear)| = %.3e\n", worst_in);
  }
  rc_scene_free(&sc);
  shp_free(&m);
}

/* ------------------------------------------------------------------ box (exact) */

static double g_box_worst;

/* compare every pixel of a box (+ optional occluder plane) scene with the slab solution */
static void box_scene_check(const char *name, const rc_scene *sc, const rc_camera *c, const double lo[3],
                            const double hi[3], const float *plane_model, double plane_h, int *nocc) {
  int px, py, n = 0;
  for (py = 0; py < c->height; py++)
    for (px = 0; px < c->width; px++) {
      double o[3], d[3], t0 = 0, t1 = 0, opaque = INFINITY, exp_th, end;
      int hit, k;
      rc_result r = rc_trace(sc, c, px + 0.5, py + 0.5);
      rc_camera_ray(c, px + 0.5, py + 0.5, o, d);
      hit = ray_box(o, d, lo, hi, &t0, &t1);
      if (plane_model) {
        /* plane = model * (z = 0), quad |x|,|y| <= plane_h */
        double p0[3], ex[3], ey[3], nn[3], q[3], tp, a, b, g11, g12, g22, r1, r2, det;
        for (k = 0; k < 3; k++) {
          p0[k] = plane_model[12 + k];
          ex[k] = plane_model[0 + k];
          ey[k] = plane_model[4 + k];
        }
        nn[0] = ex[1] * ey[2] - ex[2] * ey[1];
        nn[1] = ex[2] * ey[0] - ex[0] * ey[2];
        nn[2] = ex[0] * ey[1] - ex[1] * ey[0];
        tp = (nn[0] * (p0[0] - o[0]) + nn[1] * (p0[1] - o[1]) + nn[2] * (p0[2] - o[2])) /
             (nn[0] * d[0] + nn[1] * d[1] + nn[2] * d[2]);
        for (k = 0; k < 3; k++) q[k] = o[k] + tp * d[k] - p0[k];
        g11 = ex[0] * ex[0] + ex[1] * ex[1] + ex[2] * ex[2];
        g22 = ey[0] * ey[0] + ey[1] * ey[1] + ey[2] * ey[2];
        g12 = ex[0] * ey[0] + ex[1] * ey[1] + ex[2] * ey[2];
        r1 = q[0] * ex[0] + q[1] * ex[1] + q[2] * ex[2];
        r2 = q[0] * ey[0] + q[1] * ey[1] + q[2] * ey[2];
        det = g11 * g22 - g12 * g12;
        a = (r1 * g22 - r2 * g12) / det;
        b = (r2 * g11 - r1 * g12) / det;
        if (fabs(fabs(a) - plane_h) < 1e-6 || fabs(fabs(b) - plane_h) < 1e-6) continue; /* quad border */
        if (fabs(a) < plane_h && fabs(b) < plane_h && tp >= c->znear) opaque = tp;
        check(opaque == INFINITY ? r.opaque_w == INFINITY : fabs(r.opaque_w - opaque) <= 1e-10 * (1 + opaque),
              "%s px %d,%d opaque_w %.15g != %.15g", name, px, py, r.opaque_w, opaque);
        if (opaque < INFINITY) (*nocc)++;
      }
      end = opaque < c->zfar ? opaque : c->zfar;
      exp_th = hit ? seg(t0, t1, c->znear, end) : 0.0;
      check(fabs(r.thickness - exp_th) <= 1e-10, "%s px %d,%d th %.15g != %.15g", name, px, py, r.thickness, exp_th);
      if (fabs(r.thickness - exp_th) > g_box_worst) g_box_worst = fabs(r.thickness - exp_th);
      if (hit && t0 >= c->znear && t1 < c->zfar)
        check(r.faces_front == 1 && r.faces_back == 1, "%s px %d,%d faces %d/%d", name, px, py, r.faces_front,
              r.faces_back);
      n++;
    }
  (void)n;
}

static void test_box(void) {
  shp_mesh m = shp_box(1.0f, 0.5f, 0.75f), pl = shp_grid_plane(4.0f, 4.0f, 3);
  float T[16], S[16], model[16], R[16], pmodel[16];
  double lo[3] = {0.25 - 2, -0.5 - 0.5, 0.125 - 0.75}, hi[3] = {0.25 + 2, -0.5 + 0.5, 0.125 + 0.75};
  rc_object o[2];
  rc_scene sc;
  int nocc = 0, k;
  printf("-- box (exact, tol 1e-10)\n");
  shp_mat_translate(T, 0.25f, -0.5f, 0.125f);
  shp_mat_scale(S, 2, 1, 1);
  shp_mat_mul(model, T, S);
  o[0] = make_obj(&m, model, +1);
  check(rc_scene_init(&sc, o, 1), "rc_scene_init box");
  {
    rc_camera c = make_cam(3, 2.5, 5, 0, 0, 0, 0, 1, 0, 50, 160, 120, 0.1, 100);
    box_scene_check("box outside", &sc, &c, lo, hi, NULL, 0, &nocc);
    c.zfar = 5.9; /* far plane cutting the box */
    box_scene_check("box far-clipped", &sc, &c, lo, hi, NULL, 0, &nocc);
  }
  {
    rc_camera c = make_cam(0.3, -0.4, 0.2, 1, 0.2, -3, 0, 1, 0, 60, 96, 64, 0.1, 100);
    box_scene_check("box camera inside", &sc, &c, lo, hi, NULL, 0, &nocc);
    c = make_cam(0.25, -0.5, 0.125 + 0.75 + 0.05, 0.25, -0.4, -5, 0, 1, 0, 60, 96, 64, 0.2, 100);
    box_scene_check("box near plane cuts", &sc, &c, lo, hi, NULL, 0, &nocc);
  }
  rc_scene_free(&sc);
  /* occluder quad cutting through the box */
  shp_mat_translate(T, 0.1f, 0, 0);
  shp_mat_rotate(R, 50, 1, 0.3f, 0);
  shp_mat_mul(pmodel, T, R);
  o[1] = make_obj(&pl, pmodel, 0);
  check(rc_scene_init(&sc, o, 2), "rc_scene_init box+occluder");
  {
    rc_camera c = make_cam(3, 2.5, 5, 0, 0, 0, 0, 1, 0, 50, 160, 120, 0.1, 100);
    int before = g_fail, px, py, nonint = 0, cut = 0;
    box_scene_check("box + occluder", &sc, &c, lo, hi, pmodel, 4.0, &nocc);
    c = make_cam(-4, -1.5, -3, 0, 0, 0, 0, 1, 0, 50, 160, 120, 0.1, 100); /* from the other side */
    box_scene_check("box + occluder (back side)", &sc, &c, lo, hi, pmodel, 4.0, &nocc);
    check(nocc > 1000, "occluder covers pixels (%d)", nocc);
    /* pixels where the occluder cuts the visible box are not interior; count the band */
    c = make_cam(3, 2.5, 5, 0, 0, 0, 0, 1, 0, 50, 160, 120, 0.1, 100);
    for (py = 0; py < c.height; py++)
      for (px = 0; px < c.width; px++) {
        rc_result r = rc_trace(&sc, &c, px + 0.5, py + 0.5);
        if (!rc_interior(&sc, &c, px, py)) {
          nonint++;
          if (r.thickness > 0 && r.opaque_w < INFINITY) cut++;
        }
      }
    check(nonint > 0 && nonint < c.width * c.height / 8, "box+occluder non-interior pixels %d", nonint);
    printf("   box+occluder: %d of %d pixels non-interior (%d of them with occluded volume)\n", nonint,
           c.width * c.height, cut);
    (void)before;
  }
  rc_scene_free(&sc);
  /* two overlapping boxes in ONE mesh: winding 2 in the overlap counts twice */
  {
    shp_mesh a = shp_box(1, 1, 1), b = shp_box(1, 1, 1);
    double lo2[3] = {-1.625, -1, -1}, hi2[3] = {0.375, 1, 1}, lo3[3] = {-0.375, -0.75, -0.875},
           hi3[3] = {1.625, 1.25, 1.125}; /* float-exact translations */
    rc_camera c = make_cam(2, 3, 6, 0, 0, 0, 0, 1, 0, 45, 120, 90, 0.1, 100);
    int px, py, ntwice = 0;
    shp_mat_translate(T, -0.625f, 0, 0);
    shp_transform(&a, T);
    shp_mat_translate(T, 0.625f, 0.25f, 0.125f);
    shp_transform(&b, T);
    check(shp_append(&a, &b), "shp_append");
    o[0] = make_obj(&a, NULL, +1);
    check(rc_scene_init(&sc, o, 1), "rc_scene_init overlapping boxes");
    for (py = 0; py < c.height; py++)
      for (px = 0; px < c.width; px++) {
        double oo[3], d[3], t0, t1, e = 0;
        rc_result r = rc_trace(&sc, &c, px + 0.5, py + 0.5);
        rc_camera_ray(&c, px + 0.5, py + 0.5, oo, d);
        if (ray_box(oo, d, lo2, hi2, &t0, &t1)) e += seg(t0, t1, c.znear, c.zfar);
        if (ray_box(oo, d, lo3, hi3, &t0, &t1)) {
          e += seg(t0, t1, c.znear, c.zfar);
          if (e > seg(t0, t1, c.znear, c.zfar)) ntwice++;
        }
        check(fabs(r.thickness - e) <= 1e-10, "overlapping boxes px %d,%d th %.15g != %.15g", px, py, r.thickness, e);
        if (fabs(r.thickness - e) > g_box_worst) g_box_worst = fabs(r.thickness - e);
      }
    check(ntwice > 100, "overlap region visible (%d pixels)", ntwice);
    rc_scene_free(&sc);
    shp_free(&a);
    shp_free(&b);
  }
  for (k = 0; k < 1; k++) {
    /* invalid index -> init fails */
    unsigned bad[3] = {0, 1, 99};
    rc_object ob = make_obj(&m, NULL, 1);
    ob.idx = bad;
    ob.icount = 3;
    check(!rc_scene_init(&sc, &ob, 1) && sc.objs == NULL, "rc_scene_init rejects out-of-range index");
  }
  printf("   all box scenes: max |th - exact| = %.3e, %d occluded pixel samples checked\n", g_box_worst, nocc);
  shp_free(&m);
  shp_free(&pl);
}

/* ------------------------------------------------------------------ torus */

/* 2D line vs convex CCW polygon (Cyrus-Beck) */
static int ray_poly2(const double o[2], const double d[2], const double *px, const double *py, int n, double *t0,
                     double *t1) {
  double a = -INFINITY, b = INFINITY;
  int i;
  for (i = 0; i < n; i++) {
    int j = (i + 1) % n;
    double nx = py[j] - py[i], ny = -(px[j] - px[i]); /* outward for CCW */
    double den = nx * d[0] + ny * d[1], num = nx * (px[i] - o[0]) + ny * (py[i] - o[1]);
    if (den == 0) {
      if (num < 0) return 0;
    } else if (den > 0) {
      if (num / den < b) b = num / den;
    } else {
      if (num / den > a) a = num / den;
    }
  }
  if (a >= b) return 0;
  *t0 = a;
  *t1 = b;
  return 1;
}

static double torus_f(double R, double r, const double p[3]) {
  double q = sqrt(p[0] * p[0] + p[1] * p[1]) - R;
  return q * q + p[2] * p[2] - r * r;
}

static void test_torus(void) {
  int nu = 64, nv = 32, i, px, ntwo = 0;
  float R = 2.0f, r = 0.5f;
  shp_mesh m = shp_torus(R, r, nu, nv), mf = shp_torus(R, r, 256, 128);
  double ox[64], oy[64], ix[64], iy[64], worst = 0, worst_s = 0;
  rc_object o = make_obj(&m, NULL, +1), of = make_obj(&mf, NULL, +1);
  rc_scene sc, scf;
  rc_camera c = make_cam(0, -10, 0, 0, 0, 0, 0, 0, 1, 20, 256, 64, 0.1, 100);
  printf("-- torus R=2 r=0.5 seen edge-on (ring plane: exact polygon section, tol 1e-10; off-plane: smooth torus, "
         "256x128, tol 3e-3)\n");
  for (i = 0; i < nu; i++) {
    ox[i] = m.pos[3 * (i * nv)];
    oy[i] = m.pos[3 * (i * nv) + 1];
    ix[i] = m.pos[3 * (i * nv + nv / 2)];
    iy[i] = m.pos[3 * (i * nv + nv / 2) + 1];
  }
  check(rc_scene_init(&sc, &o, 1) && rc_scene_init(&scf, &of, 1), "rc_scene_init torus");
  for (px = 0; px <= 2 * c.width; px++) {
    double sx = px * 0.5, o3[3], d[3], t0, t1, e = 0;
    rc_result res = rc_trace(&sc, &c, sx, c.height / 2.0);
    rc_camera_ray(&c, sx, c.height / 2.0, o3, d);
    check(d[2] == 0.0, "ring-plane ray has dz = 0");
    if (ray_poly2(o3, d, ox, oy, nu, &t0, &t1)) {
      e += t1 - t0;
      if (ray_poly2(o3, d, ix, iy, nu, &t0, &t1)) {
        e -= t1 - t0;
        ntwo++;
      }
    }
    check(fabs(res.thickness - e) <= 1e-10, "torus ring plane sx %.1f th %.15g != %.15g", sx, res.thickness, e);
    if (fabs(res.thickness - e) > worst) worst = fabs(res.thickness - e);
    if (sx == c.width / 2.0)
      check(fabs(e - 2.0 * (oy[nu / 4] - iy[nu / 4])) < 1e-6 && fabs(e - 2.0) < 1e-6,
            "central ray: two tube chords %.9f != 2*2r", e);
  }
  check(ntwo > 50, "rays through both tubes (%d)", ntwo);
  /* slightly off the ring plane vs the smooth torus (root finding along the ray) */
  for (px = 96; px < 160; px++) {
    double sy = c.height / 2.0 + 3.2, o3[3], d[3], e = 0, tprev = 5, fprev, t;
    rc_result res = rc_trace(&scf, &c, px + 0.5, sy);
    int sgn = 0;
    rc_camera_ray(&c, px + 0.5, sy, o3, d);
    {
      double p[3] = {o3[0] + tprev * d[0], o3[1] + tprev * d[1], o3[2] + tprev * d[2]};
      fprev = torus_f(R, r, p);
    }
    for (t = 5.0005; t <= 15; t += 0.0005) {
      double p[3] = {o3[0] + t * d[0], o3[1] + t * d[1], o3[2] + t * d[2]}, f = torus_f(R, r, p);
      if ((f < 0) != (fprev < 0)) {
        double a = tprev, b = t;
        int it;
        for (it = 0; it < 60; it++) {
          double mm = 0.5 * (a + b), q[3] = {o3[0] + mm * d[0], o3[1] + mm * d[1], o3[2] + mm * d[2]};
          if ((torus_f(R, r, q) < 0) == (fprev < 0))
            a = mm;
          else
            b = mm;
        }
        e += (f < 0) ? -0.5 * (a + b) : 0.5 * (a + b);
        sgn += (f < 0) ? 1 : -1;
      }
      tprev = t;
      fprev = f;
    }
    check(sgn == 0, "smooth torus root finding closed");
    check(fabs(res.thickness - e) <= 3e-3, "torus off-plane px %d th %.6f != smooth %.6f", px, res.thickness, e);
    if (fabs(res.thickness - e) > worst_s) worst_s = fabs(res.thickness - e);
    if (px == 128) check(res.faces_front == 2 && res.faces_back == 2, "torus central faces %d/%d", res.faces_front, res.faces_back);
  }
  printf("   ring plane: %d rays through both tubes, max |th - exact| = %.3e; off-plane max |th - smooth| = %.3e\n",
         ntwo, worst, worst_s);
  rc_scene_free(&sc);
  rc_scene_free(&scf);
  shp_free(&m);
  shp_free(&mf);
}

/* ------------------------------------------------------------------ negative sphere in box */

static void test_negative(void) {
  shp_mesh b = shp_box(1, 1, 1), s = shp_sphere(0.5f, 128, 64);
  float model[16];
  double cen[3] = {0.1, 0.05, -0.1}, lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1}, rin = 0.5 * mesh_min_plane_dist(&s) / 0.5,
         rout = 0.5 * (1 + 1e-6), tol = 1e-6, worst = 0;
  rc_object o[2];
  rc_scene sc;
  rc_camera c = make_cam(2.5, 1.5, 4, 0, 0, 0, 0, 1, 0, 45, 128, 96, 0.1, 100);
  int px, py, nboth = 0;
  printf("-- negative sphere (r=0.5, 128x64) inside a positive box: box chord - sphere chord\n");
  shp_mat_translate(model, 0.1f, 0.05f, -0.1f);
  o[0] = make_obj(&b, NULL, +1);
  o[1] = make_obj(&s, model, -1);
  check(rc_scene_init(&sc, o, 2), "rc_scene_init negative");
  for (py = 0; py < c.height; py++)
    for (px = 0; px < c.width; px++) {
      double oo[3], d[3], t0, t1, box = 0, a0, a1, b0, b1, smin = 0, smax = 0;
      rc_result r = rc_trace(&sc, &c, px + 0.5, py + 0.5);
      rc_camera_ray(&c, px + 0.5, py + 0.5, oo, d);
      if (ray_box(oo, d, lo, hi, &t0, &t1)) box = seg(t0, t1, c.znear, c.zfar);
      if (ray_sphere(oo, d, cen, rout, &a0, &a1)) smax = a1 - a0;
      if (ray_sphere(oo, d, cen, rin, &b0, &b1)) {
        smin = b1 - b0;
        nboth++;
        check(r.faces_front == 2 && r.faces_back == 2, "negative px %d,%d faces %d/%d", px, py, r.faces_front,
              r.faces_back);
        if (fabs(r.thickness - (box - smax)) > worst) worst = fabs(r.thickness - (box - smax));
      }
      check(r.thickness >= box - smax - tol && r.thickness <= box - smin + tol,
            "negative px %d,%d th %.9f not in [%.9f, %.9f]", px, py, r.thickness, box - smax, box - smin);
    }
  check(nboth > 300, "rays through the negative sphere (%d)", nboth);
  printf("   %d rays through both: max |th - (box - exact sphere chord)| = %.3e (r_in %.6f)\n", nboth, worst, rin);
  rc_scene_free(&sc);
  shp_free(&b);
  shp_free(&s);
}


/* ------------------------------------------------------------------ exact ties */

/* Rays exactly through vertices / edges (bit-exact in floating point). The fold case is a
   bipyramid over a simple but non-star-shaped pentagon: seen from above, the apex fan
   contains one clockwise (back-facing) triangle, yet the vertical ray through the apex
   crosses the surface exactly once there (winding number of the projected link = 1). */
static void test_ties(void) {
  static const double ang[5] = {0, 100, 80, 200, 300}, rad[5] = {1, 1, 0.5, 1, 1};
  float pos[7 * 3];
  unsigned idx[10 * 3];
  shp_mesh fold;
  rc_object o;
  rc_scene sc;
  rc_result r;
  int k, eu;
  char why[256];
  printf("-- exact ties (rays through vertices / edges)\n");
  pos[0] = pos[1] = pos[2] = 0;
  for (k = 0; k < 5; k++) {
    pos[3 + 3 * k] = (float)(rad[k] * cos(ang[k] * PI / 180));
    pos[3 + 3 * k + 1] = (float)(rad[k] * sin(ang[k] * PI / 180));
    pos[3 + 3 * k + 2] = -1;
  }
  pos[18] = pos[19] = 0;
  pos[20] = -2;
  for (k = 0; k < 5; k++) {
    idx[3 * k] = 0;
    idx[3 * k + 1] = (unsigned)(1 + k);
    idx[3 * k + 2] = (unsigned)(1 + (k + 1) % 5);
    idx[15 + 3 * k] = 6;
    idx[15 + 3 * k + 1] = (unsigned)(1 + (k + 1) % 5);
    idx[15 + 3 * k + 2] = (unsigned)(1 + k);
  }
  fold.pos = pos;
  fold.vcount = 7;
  fold.idx = idx;
  fold.icount = 30;
  check(mesh_closed(&fold, &eu, why, sizeof why) && eu == 2 && mesh_volume(&fold) > 0, "fold bipyramid mesh: %s", why);
  o = make_obj(&fold, NULL, +1);
  check(rc_scene_init(&sc, &o, 1), "rc_scene_init fold");
  {
    rc_camera c = make_cam(0, 0, 5, 0, 0, 0, 0, 1, 0, 30, 64, 64, 0.1, 100);
    r = rc_trace(&sc, &c, 32, 32);
    check(r.thickness == 2.0, "fold: vertical ray through both apexes: th %.17g != 2", r.thickness);
    /* the tie-break counts the crossings of a nearby generic ray: here 3 = 2 front + 1 back
       triangles at the top apex (net +1) and 1 front + 2 back at the bottom one (net -1) */
    check(r.faces_front == r.faces_back && (r.faces_front == 1 || r.faces_front == 3), "fold: faces %d/%d",
          r.faces_front, r.faces_back);
    printf("   fold apex (mixed-orientation fan): th %.17g (exact 2), faces %d/%d\n", r.thickness, r.faces_front,
           r.faces_back);
  }
  rc_scene_free(&sc);
  {
    shp_mesh s = shp_sphere(1.0f, 128, 64);
    rc_camera c = make_cam(0, 0, 5, 0, 0, 0, 0, 1, 0, 30, 64, 64, 0.1, 100);
    o = make_obj(&s, NULL, +1);
    check(rc_scene_init(&sc, &o, 1), "rc_scene_init sphere");
    r = rc_trace(&sc, &c, 32, 32);
    check(fabs(r.thickness - 2.0) < 1e-14 && r.faces_front == 1 && r.faces_back == 1,
          "sphere: ray through both 128-triangle pole fans: th %.17g faces %d/%d", r.thickness, r.faces_front,
          r.faces_back);
    printf("   sphere pole to pole through 128-fans: th %.17g (exact 2), faces %d/%d\n", r.thickness, r.faces_front,
           r.faces_back);
    rc_scene_free(&sc);
    shp_free(&s);
  }
  {
    shp_mesh b = shp_box(1, 1, 1);
    rc_camera c = make_cam(3, 3, 0.5, 0, 0, 0.5, 0, 0, 1, 30, 64, 64, 0.1, 100);
    o = make_obj(&b, NULL, +1);
    check(rc_scene_init(&sc, &o, 1), "rc_scene_init box");
    r = rc_trace(&sc, &c, 32, 32);
    check(fabs(r.thickness - 2 * sqrt(2.0)) < 1e-14 && r.faces_front == 1 && r.faces_back == 1,
          "box: ray through two opposite edges: th %.17g faces %d/%d", r.thickness, r.faces_front, r.faces_back);
    printf("   box edge to edge: th %.17g (exact %.17g), faces %d/%d\n", r.thickness, 2 * sqrt(2.0), r.faces_front,
           r.faces_back);
    c = make_cam(1, 1, 5, 1, 1, 0, 0, 1, 0, 30, 64, 64, 0.1, 100);
    r = rc_trace(&sc, &c, 32, 32);
    check(r.thickness == 0.0 || r.thickness == 2.0, "box: ray along an edge: th %.17g", r.thickness);
    printf("   box ray along its vertical edge (grazing, measure zero): th %.17g, faces %d/%d\n", r.thickness,
           r.faces_front, r.faces_back);
    c = make_cam(3, 3, 3, 0, 0, 0, 0, 1, 0, 30, 64, 64, 0.1, 100);
    r = rc_trace(&sc, &c, 32, 32);
    check(fabs(r.thickness - 2 * sqrt(3.0)) < 1e-12 && r.faces_front == 1 && r.faces_back == 1,
          "box: ray through two opposite corners: th %.17g faces %d/%d", r.thickness, r.faces_front, r.faces_back);
    printf("   box corner to corner: th %.17g (exact %.17g), faces %d/%d\n", r.thickness, 2 * sqrt(3.0),
           r.faces_front, r.faces_back);
    rc_scene_free(&sc);
    shp_free(&b);
  }
}


/* ------------------------------------------------------------------ winding invariants */

/* For an embedded, closed, outward-oriented mesh every line must see the winding count go
   0 -> 1 -> 0 -> ... (in {0,1} between distinct t, 0 at the end), also for rays that pass
   EXACTLY through vertices (axis-aligned rays through every vertex) and for random rays.
   Uses raycast.h internals (rc__ray_setup, rc__object_hits, rc__sort). */
static int winding_ok(const rc_scene_object *so, const double o[3], const double d[3], int *nhits) {
  rc__ray ray;
  rc__hitbuf buf;
  int k, cnt = 0, ok = 1;
  rc__ray_setup(&ray, o, d);
  rc__hitbuf_init(&buf);
  rc__object_hits(so, &ray, -INFINITY, INFINITY, &buf);
  rc__sort(&buf);
  for (k = 0; k < buf.n; k++) {
    cnt += buf.h[k].enter ? 1 : -1;
    /* grazing a fold gives an enter/exit pair at the same t whose order is decided by rounding
       (|dt| ~ 1e-16): only intervals that carry weight in the integral are checked */
    if ((k + 1 == buf.n || buf.h[k + 1].t > buf.h[k].t + 1e-12 * (fabs(buf.h[k].t) + 1)) && (cnt < 0 || cnt > 1))
      ok = 0;
  }
  if (cnt != 0 || buf.oom) ok = 0;
  *nhits += buf.n;
  rc__hitbuf_free(&buf);
  return ok;
}

static unsigned g_rng = 12345u;
static double frand(void) {
  g_rng = g_rng * 1664525u + 1013904223u;
  return (g_rng >> 8) / 16777216.0;
}

static void test_winding(void) {
  shp_mesh ms[5];
  const char *names[5] = {"sphere 32x16", "box", "torus 24x12", "torus knot (2,3)", "torus knot (3,5)"};
  int s;
  printf("-- winding invariants (exact vertex rays along +-x,+-y,+-z through every vertex; random rays)\n");
  ms[0] = shp_sphere(1, 32, 16);
  ms[1] = shp_box(1, 0.5f, 0.25f);
  ms[2] = shp_torus(1, 0.4f, 24, 12);
  ms[3] = shp_torus_knot(2, 3, 1, 0.4f, 0.12f, 128, 8);
  ms[4] = shp_torus_knot(3, 5, 1, 0.35f, 0.07f, 200, 6);
  for (s = 0; s < 5; s++) {
    rc_object o = make_obj(&ms[s], NULL, +1);
    rc_scene sc;
    int v, a, bad = 0, rays = 0, hits = 0, i;
    if (!rc_scene_init(&sc, &o, 1)) {
      check(0, "rc_scene_init %s", names[s]);
      continue;
    }
    for (v = 0; v < ms[s].vcount; v++)
      for (a = 0; a < 6; a++) {
        double org[3], d[3] = {0, 0, 0};
        int k;
        for (k = 0; k < 3; k++) org[k] = ms[s].pos[3 * v + k];
        d[a % 3] = a < 3 ? 1.0 : -1.0;
        org[a % 3] -= 5 * d[a % 3];
        bad += !winding_ok(&sc.objs[0], org, d, &hits);
        rays++;
      }
    for (i = 0; i < 20000; i++) {
      double org[3], d[3];
      int k;
      for (k = 0; k < 3; k++) {
        org[k] = frand() * 6 - 3;
        d[k] = frand() * 2 - 1;
      }
      bad += !winding_ok(&sc.objs[0], org, d, &hits);
      rays++;
    }
    check(bad == 0, "%s: winding invariant broken on %d of %d rays", names[s], bad, rays);
    printf("   %-17s %6d rays, %7d crossings, %d bad\n", names[s], rays, hits, bad);
    rc_scene_free(&sc);
  }
  for (s = 0; s < 5; s++) shp_free(&ms[s]);
}

/* ------------------------------------------------------------------ rc_interior's memo */

/* rc_interior keeps its samples' signatures with the scene, per camera: with two cameras taking
   turns pixel by pixel (each turn a new generation of the memo), every pixel's answer must be the
   definition's, evaluated here with rc_trace alone. */
static void test_interior_memo(void) {
  shp_mesh m = shp_torus(1.0f, 0.35f, 24, 12);
  rc_object o = make_obj(&m, NULL, +1);
  rc_scene sc;
  rc_camera c[2];
  const double off[12][2] = {{0, 0},      {1, 0},     {0, 1},     {1, 1},    {-0.5, -0.5}, {0.5, -0.5},
                             {1.5, -0.5}, {-0.5, 0.5}, {1.5, 0.5}, {-0.5, 1.5}, {0.5, 1.5},  {1.5, 1.5}};
  int px, py, k, i, diff = 0, nint[2] = {0, 0};
  printf("-- rc_interior's memo\n");
  c[0] = make_cam(0.3, 1.2, 2.6, 0, 0, 0, 0, 1, 0, 60, 48, 40, 0.1, 100);
  c[1] = make_cam(-1.9, 0.4, 1.7, 0, 0.1, 0, 0, 1, 0, 50, 48, 40, 0.1, 100);
  check(rc_scene_init(&sc, &o, 1), "rc_scene_init memo");
  for (py = 0; py < 40; py++)
    for (px = 0; px < 48; px++)
      for (k = 0; k < 2; k++) {
        unsigned s0 = rc_trace(&sc, &c[k], px + 0.5, py + 0.5).signature;
        int want = 1;
        for (i = 0; i < 12; i++) want &= rc_trace(&sc, &c[k], px + off[i][0], py + off[i][1]).signature == s0;
        diff += rc_interior(&sc, &c[k], px, py) != want;
        nint[k] += want;
      }
  check(diff == 0 && nint[0] > 100 && nint[0] < 48 * 40 && nint[1] > 100 && nint[1] < 48 * 40,
        "rc_interior with two cameras in turn: %d of %d answers differ from the definition (%d and %d interior)", diff,
        2 * 48 * 40, nint[0], nint[1]);
  printf("   two cameras in turn, 48x40: %d of %d answers differ from rc_trace's (%d, %d interior)\n", diff,
         2 * 48 * 40, nint[0], nint[1]);
  rc_scene_free(&sc);
  shp_free(&m);
}

/* ------------------------------------------------------------------ performance */

static void test_perf(void) {
  shp_mesh m = shp_sphere(1.0f, 40, 26);
  rc_object o = make_obj(&m, NULL, +1);
  rc_scene sc;
  rc_camera c = make_cam(0.3, 0.2, 2.6, 0, 0, 0, 0, 1, 0, 60, 128, 128, 0.1, 100);
  clock_t t0 = clock();
  int px, py, nint = 0;
  double sum = 0, secs;
  printf("-- performance\n");
  check(m.icount / 3 == 2000, "perf mesh has 2000 triangles");
  check(rc_scene_init(&sc, &o, 1), "rc_scene_init perf");
  for (py = 0; py < c.height; py++)
    for (px = 0; px < c.width; px++) {
      sum += rc_trace(&sc, &c, px + 0.5, py + 0.5).thickness;
      nint += rc_interior(&sc, &c, px, py);
    }
  secs = (double)(clock() - t0) / CLOCKS_PER_SEC;
  printf("   128x128, 2000 triangles, rc_trace + rc_interior per pixel (14 samples, each point traced once per "
         "camera): %.3f s CPU (%d interior, sum %.3f)\n",
         secs, nint, sum);
  rc_scene_free(&sc);
  shp_free(&m);
}

/* rc_depth_slope against the closed form: a unit box turned 30 degrees about y, 5 units ahead;
   the centre ray crosses its front and back faces, planes n.p = d, where the view depth along the
   ray dir(sx) = f + x tx r (x = 2 sx / width - 1) is w = d / (n.dir), so
   dw/dsx = -d (n.r) tx (2 / width) / (n.dir)^2 and dw/dsy = 0 (n has no y part). */
static void test_depth_slope(void) {
  const int W = 64, H = 64;
  rc_camera c = make_cam(0, 0, 0, 0, 0, -1, 0, 1, 0, 60.0, W, H, 0.1, 100.0);
  shp_mesh box = shp_box(1.0f, 1.0f, 1.0f);
  float model[16];
  double tx = tan(30.0 * PI / 180.0), want = 0.0, got, cs, sn;
  rc_object o;
  rc_scene sc;
  int k;
  shp_mat_identity(model);
  cs = (double)(float)cos(PI / 6.0);
  sn = (double)(float)sin(PI / 6.0);
  model[0] = (float)cs, model[2] = (float)-sn, model[8] = (float)sn, model[10] = (float)cs, model[14] = -5.0f;
  o = make_obj(&box, model, 1);
  check(rc_scene_init(&sc, &o, 1), "depth slope: scene");
  for (k = -1; k <= 1; k += 2) { /* the faces z = +-1 of the box: n = R (0, 0, k), through c + n */
    double n[3] = {sn * k, 0.0, cs * k}, d = n[2] * -5.0 + 1.0, x = 2.0 * (31 + 0.5) / W - 1.0;
    double ndir = -n[2] + x * tx * n[0];
    want += fabs(-d * n[0] * tx * (2.0 / W) / (ndir * ndir));
  }
  got = rc_depth_slope(&sc, &c, 31, 31);
  check(fabs(got - want) <= 1e-4 * want, "depth slope at the centre %.9g != closed form %.9g", got, want);
  check(rc_depth_slope(&sc, &c, 0, 0) == 0.0, "depth slope where nothing is crossed: %g", rc_depth_slope(&sc, &c, 0, 0));
  printf("   rc_depth_slope: %.9g vs closed form %.9g view units per pixel\n", got, want);
  rc_scene_free(&sc);
  shp_free(&box);
}

int main(void) {
  test_meshes();
  test_camera();
  test_sphere();
  test_box();
  test_torus();
  test_negative();
  test_ties();
  test_winding();
  test_depth_slope();
  test_interior_memo();
  test_perf();
  printf("%d passed, %d failed\n", g_pass, g_fail);
  return g_fail ? 1 : 0;
}
