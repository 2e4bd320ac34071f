/* shapes.h - closed triangle mesh generators for fogvol tests (header-only, C99 / C++11).
 *
 * Every closed mesh produced here is a closed, manifold, consistently oriented hull with
 * shared vertices: every undirected edge is used by exactly two triangles, in opposite
 * directions; triangles are counter-clockwise seen from OUTSIDE (outward normal by the
 * right-hand rule, n = (b-a) x (c-a)); there are no degenerate triangles (poles are fans).
 *
 * Memory comes from malloc; release with shp_free(). On allocation failure or invalid
 * parameters a zeroed mesh (pos == NULL, vcount == 0, idx == NULL, icount == 0) is returned.
 *
 * Matrices are column-major float[16] (m[col*4+row]), as glUniformMatrix4fv(transpose=false).
 */
#ifndef SHAPES_H
#define SHAPES_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SHP__FN static inline
#define SHP__PI 3.14159265358979323846
#define SHP__MAXCOUNT 0x0fffffff /* guard against int overflow in vertex/index counts */

typedef struct shp_mesh {
  float *pos;     /* xyz packed, 3*vcount floats */
  int vcount;
  unsigned *idx;  /* triangles, icount indices (icount % 3 == 0) */
  int icount;
} shp_mesh;

SHP__FN shp_mesh shp__zero(void) {
  shp_mesh m;
  memset(&m, 0, sizeof m);
  return m;
}

SHP__FN shp_mesh shp__alloc(double vcount, double icount) {
  shp_mesh m = shp__zero();
  if (vcount <= 0 || icount <= 0 || vcount > SHP__MAXCOUNT || icount > SHP__MAXCOUNT) return m;
  m.pos = (float *)malloc((size_t)vcount * 3 * sizeof(float));
  m.idx = (unsigned *)malloc((size_t)icount * sizeof(unsigned));
  if (!m.pos || !m.idx) {
    free(m.pos);
    free(m.idx);
    return shp__zero();
  }
  m.vcount = (int)vcount;
  m.icount = (int)icount;
  return m;
}

SHP__FN void shp_free(shp_mesh *m) {
  if (!m) return;
  free(m->pos);
  free(m->idx);
  memset(m, 0, sizeof *m);
}

SHP__FN void shp__setv(shp_mesh *m, int i, double x, double y, double z) {
  m->pos[3 * i + 0] = (float)x;
  m->pos[3 * i + 1] = (float)y;
  m->pos[3 * i + 2] = (float)z;
}

SHP__FN void shp__tri(unsigned **p, int a, int b, int c) {
  (*p)[0] = (unsigned)a;
  (*p)[1] = (unsigned)b;
  (*p)[2] = (unsigned)c;
  *p += 3;
}

/* quad a,b,c,d counter-clockwise seen from the side the normal points to */
SHP__FN void shp__quad(unsigned **p, int a, int b, int c, int d) {
  shp__tri(p, a, b, c);
  shp__tri(p, a, c, d);
}

/* UV sphere of radius r centred at the origin, poles on the z axis (single shared pole
   vertices, triangle fans there). slices >= 3 (around z), stacks >= 2 (pole to pole).
   vcount = 2 + slices*(stacks-1), triangles = 2*slices*(stacks-1). */
SHP__FN shp_mesh shp_sphere(float r, int slices, int stacks) {
  shp_mesh m;
  unsigned *p;
  int i, j, top, bot;
  if (slices < 3 || stacks < 2 || !(r > 0)) return shp__zero();
  m = shp__alloc(2.0 + (double)slices * (stacks - 1), 6.0 * slices * (stacks - 1));
  if (!m.pos) return m;
  top = 0;
  bot = m.vcount - 1;
  shp__setv(&m, top, 0, 0, r);
  shp__setv(&m, bot, 0, 0, -r);
  for (i = 1; i < stacks; i++) {
    double th = SHP__PI * i / stacks, st = sin(th), ct = cos(th);
    for (j = 0; j < slices; j++) {
      double ph = 2.0 * SHP__PI * j / slices;
      shp__setv(&m, 1 + (i - 1) * slices + j, r * st * cos(ph), r * st * sin(ph), r * ct);
    }
  }
#define SHP__SV(i, j) (1 + ((i) - 1) * slices + ((j) % slices))
  p = m.idx;
  for (j = 0; j < slices; j++) shp__tri(&p, top, SHP__SV(1, j), SHP__SV(1, j + 1));
  for (i = 1; i < stacks - 1; i++)
    for (j = 0; j < slices; j++)
      shp__quad(&p, SHP__SV(i, j), SHP__SV(i + 1, j), SHP__SV(i + 1, j + 1), SHP__SV(i, j + 1));
  for (j = 0; j < slices; j++) shp__tri(&p, SHP__SV(stacks - 1, j), bot, SHP__SV(stacks - 1, j + 1));
#undef SHP__SV
  return m;
}

/* Axis-aligned box centred at the origin: 8 vertices, 12 triangles.
   Vertex i = (i&1 ? +hx : -hx, i&2 ? +hy : -hy, i&4 ? +hz : -hz). */
SHP__FN shp_mesh shp_box(float hx, float hy, float hz) {
  shp_mesh m;
  unsigned *p;
  int i;
  if (!(hx > 0) || !(hy > 0) || !(hz > 0)) return shp__zero();
  m = shp__alloc(8, 36);
  if (!m.pos) return m;
  for (i = 0; i < 8; i++)
    shp__setv(&m, i, (i & 1) ? hx : -hx, (i & 2) ? hy : -hy, (i & 4) ? hz : -hz);
  p = m.idx;
  shp__quad(&p, 1, 3, 7, 5); /* +x */
  shp__quad(&p, 0, 4, 6, 2); /* -x */
  shp__quad(&p, 2, 6, 7, 3); /* +y */
  shp__quad(&p, 0, 1, 5, 4); /* -y */
  shp__quad(&p, 4, 5, 7, 6); /* +z */
  shp__quad(&p, 0, 2, 3, 1); /* -z */
  return m;
}

/* Capped cylinder around the y axis, radius r, from y = -hy to +hy, n >= 3 sides; 2n + 2 vertices:
   bottom ring i = (r cos a, -hy, r sin a), top ring n + i, a = 2 pi i / n, then the caps' centres. */
SHP__FN shp_mesh shp_cylinder(float r, float hy, int n) {
  shp_mesh m;
  unsigned *p;
  int i, bc = 2 * n, tc = 2 * n + 1;
  if (n < 3 || !(r > 0) || !(hy > 0)) return shp__zero();
  m = shp__alloc(2.0 * n + 2, 12.0 * n);
  if (!m.pos) return m;
  for (i = 0; i < n; i++) {
    double a = 2.0 * SHP__PI * i / n;
    shp__setv(&m, i, r * cos(a), -hy, r * sin(a));
    shp__setv(&m, n + i, r * cos(a), hy, r * sin(a));
  }
  shp__setv(&m, bc, 0, -hy, 0);
  shp__setv(&m, tc, 0, hy, 0);
  p = m.idx;
  for (i = 0; i < n; i++) {
    int j = (i + 1) % n;
    shp__tri(&p, i, n + i, n + j);
    shp__tri(&p, i, n + j, j);
    shp__tri(&p, tc, n + j, n + i);
    shp__tri(&p, bc, i, j);
  }
  return m;
}

/* Torus around the z axis (ring in the xy plane), major radius R, tube radius r (0 < r < R).
   nu >= 3 segments around the ring, nv >= 3 around the tube.
   Vertex (i,j) = ((R + r cos v) cos u, (R + r cos v) sin u, r sin v), u = 2 pi i/nu, v = 2 pi j/nv,
   index i*nv + j. */
SHP__FN shp_mesh shp_torus(float R, float r, int nu, int nv) {
  shp_mesh m;
  unsigned *p;
  int i, j;
  if (nu < 3 || nv < 3 || !(r > 0) || !(R > r)) return shp__zero();
  m = shp__alloc((double)nu * nv, 6.0 * nu * nv);
  if (!m.pos) return m;
  for (i = 0; i < nu; i++) {
    double u = 2.0 * SHP__PI * i / nu, cu = cos(u), su = sin(u);
    for (j = 0; j < nv; j++) {
      double v = 2.0 * SHP__PI * j / nv, rho = R + r * cos(v);
      shp__setv(&m, i * nv + j, rho * cu, rho * su, r * sin(v));
    }
  }
  p = m.idx;
  for (i = 0; i < nu; i++) {
    int i1 = (i + 1) % nu;
    for (j = 0; j < nv; j++) {
      int j1 = (j + 1) % nv;
      shp__quad(&p, i * nv + j, i1 * nv + j, i1 * nv + j1, i * nv + j1);
    }
  }
  return m;
}

SHP__FN void shp__knot_curve(int p, int q, double R, double r, double t, double c[3], double d[3]) {
  double cq = cos(q * t), sq = sin(q * t), cp = cos(p * t), sp = sin(p * t);
  double rho = R + r * cq;
  c[0] = rho * cp;
  c[1] = rho * sp;
  c[2] = r * sq;
  d[0] = -r * q * sq * cp - rho * p * sp;
  d[1] = -r * q * sq * sp + rho * p * cp;
  d[2] = r * q * cq;
}

SHP__FN void shp__cross(const double a[3], const double b[3], double o[3]) {
  double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
  o[0] = x;
  o[1] = y;
  o[2] = z;
}

SHP__FN double shp__dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

SHP__FN void shp__normalize(double a[3]) {
  double l = sqrt(shp__dot(a, a));
  if (l > 0) {
    a[0] /= l;
    a[1] /= l;
    a[2] /= l;
  }
}

/* rotate v by the minimal rotation taking unit vector a to unit vector b (Rodrigues) */
SHP__FN void shp__transport(const double a[3], const double b[3], double v[3]) {
  double k[3], kv[3], c = shp__dot(a, b), s2, f, kd;
  shp__cross(a, b, k);
  s2 = shp__dot(k, k);
  if (s2 < 1e-30) return;
  shp__cross(k, v, kv);
  kd = shp__dot(k, v);
  f = (1.0 - c) / s2;
  v[0] = v[0] * c + kv[0] + k[0] * kd * f;
  v[1] = v[1] * c + kv[1] + k[1] * kd * f;
  v[2] = v[2] * c + kv[2] + k[2] * kd * f;
}

/* Closed tube of radius `tube` along the (p,q) torus knot
     c(t) = ((R + r cos qt) cos pt, (R + r cos qt) sin pt, r sin qt),  t in [0, 2 pi)
   (p, q coprime for a knot; r < R). The frame is parallel transported along the curve and
   the residual holonomy angle is distributed evenly along it, so the tube closes without a
   twist seam. Self-intersection free when `tube` is below the curve's minimum radius of
   curvature and the strands' clearance, e.g. (2,3,R=1,r=0.4,tube=0.12) or (3,2,1,0.4,0.1).
   segments >= 3 rings along the curve, sides >= 3 vertices per ring; vertex (i,k) = i*sides+k. */
SHP__FN shp_mesh shp_torus_knot(int p, int q, float R, float r, float tube, int segments, int sides) {
  shp_mesh m;
  double *fr; /* per ring: centre[3], T[3], N[3] */
  double n0[3], nend[3], t0[3], ax[3], twist;
  unsigned *ip;
  int i, k;
  if (segments < 3 || sides < 3 || !(tube > 0) || !(r > 0) || !(R > r) || (p == 0 && q == 0))
    return shp__zero();
  m = shp__alloc((double)segments * sides, 6.0 * segments * sides);
  if (!m.pos) return m;
  fr = (double *)malloc((size_t)segments * 9 * sizeof(double));
  if (!fr) {
    shp_free(&m);
    return m;
  }
  for (i = 0; i < segments; i++) {
    double t = 2.0 * SHP__PI * i / segments;
    shp__knot_curve(p, q, R, r, t, fr + 9 * i, fr + 9 * i + 3);
    shp__normalize(fr + 9 * i + 3);
  }
  /* initial normal: perpendicular to T0 */
  {
    const double *T = fr + 3;
    double a[3] = {1, 0, 0};
    if (fabs(T[0]) > 0.6) {
      a[0] = 0;
      a[1] = 1;
    }
    shp__cross(T, a, n0);
    shp__normalize(n0);
    memcpy(fr + 6, n0, sizeof n0);
  }
  for (i = 1; i < segments; i++) {
    double *N = fr + 9 * i + 6;
    const double *T = fr + 9 * i + 3;
    double d;
    memcpy(N, fr + 9 * (i - 1) + 6, 3 * sizeof(double));
    shp__transport(fr + 9 * (i - 1) + 3, T, N);
    d = shp__dot(N, T); /* re-orthogonalise against drift */
    N[0] -= d * T[0];
    N[1] -= d * T[1];
    N[2] -= d * T[2];
    shp__normalize(N);
  }
  /* transport back to the start and measure the holonomy */
  memcpy(nend, fr + 9 * (segments - 1) + 6, sizeof nend);
  memcpy(t0, fr + 3, sizeof t0);
  shp__transport(fr + 9 * (segments - 1) + 3, t0, nend);
  shp__cross(n0, nend, ax);
  twist = atan2(shp__dot(ax, t0), shp__dot(n0, nend));
  for (i = 0; i < segments; i++) {
    const double *C = fr + 9 * i, *T = fr + 9 * i + 3;
    double *N = fr + 9 * i + 6, B[3], N2[3], a = -twist * i / segments;
    shp__cross(T, N, B);
    N2[0] = cos(a) * N[0] + sin(a) * B[0];
    N2[1] = cos(a) * N[1] + sin(a) * B[1];
    N2[2] = cos(a) * N[2] + sin(a) * B[2];
    shp__normalize(N2);
    shp__cross(T, N2, B);
    for (k = 0; k < sides; k++) {
      double ang = 2.0 * SHP__PI * k / sides, ca = cos(ang), sa = sin(ang);
      shp__setv(&m, i * sides + k, C[0] + tube * (ca * N2[0] + sa * B[0]),
                C[1] + tube * (ca * N2[1] + sa * B[1]), C[2] + tube * (ca * N2[2] + sa * B[2]));
    }
  }
  free(fr);
  ip = m.idx;
  for (i = 0; i < segments; i++) {
    int i1 = (i + 1) % segments;
    for (k = 0; k < sides; k++) {
      int k1 = (k + 1) % sides;
      /* d/d(angle) x d/d(curve) points outwards */
      shp__quad(&ip, i * sides + k, i * sides + k1, i1 * sides + k1, i1 * sides + k);
    }
  }
  return m;
}

/* OPEN n x n quad grid in the xy plane, [-hx,hx] x [-hy,hy], z = 0, normal +z
   (counter-clockwise seen from +z). Not closed: use it as an opaque occluder only.
   vcount = (n+1)^2, triangles = 2 n^2. */
SHP__FN shp_mesh shp_grid_plane(float hx, float hy, int n) {
  shp_mesh m;
  unsigned *p;
  int i, j;
  if (n < 1 || !(hx > 0) || !(hy > 0)) return shp__zero();
  m = shp__alloc((double)(n + 1) * (n + 1), 6.0 * n * n);
  if (!m.pos) return m;
  for (j = 0; j <= n; j++)
    for (i = 0; i <= n; i++)
      shp__setv(&m, j * (n + 1) + i, -hx + 2.0 * hx * i / n, -hy + 2.0 * hy * j / n, 0);
  p = m.idx;
  for (j = 0; j < n; j++)
    for (i = 0; i < n; i++) {
      int a = j * (n + 1) + i;
      shp__quad(&p, a, a + 1, a + n + 2, a + n + 1);
    }
  return m;
}

/* Cube [-h,h]^3 whose six faces are n x n quad grids with vertices of their own, (n+1)^2 a face
   (edges and corners repeated, as per-face normals or UVs make engines export cubes): closed only
   after welding (fogvol_mesh_desc.weld_distance). The repeated vertices are bit-identical.
   vcount = 6 (n+1)^2, triangles = 12 n^2, counter-clockwise seen from outside. */
SHP__FN shp_mesh shp_cube_faces(float h, int n) {
  shp_mesh m;
  unsigned *p;
  int f, i, j, k = n + 1;
  if (n < 1 || !(h > 0)) return shp__zero();
  m = shp__alloc(6.0 * k * k, 36.0 * n * n);
  if (!m.pos) return m;
  p = m.idx;
  for (f = 0; f < 6; f++) { /* normal axis a = f / 2, sign + for even f; in-plane axes u, v with u x v = a */
    int a = f / 2, u = (a + 1) % 3, v = (a + 2) % 3, base = f * k * k;
    double s = (f & 1) ? -1.0 : 1.0;
    for (j = 0; j <= n; j++)
      for (i = 0; i <= n; i++) {
        double c[3];
        c[a] = s * h;
        c[u] = -h + 2.0 * h * i / n;
        c[v] = -h + 2.0 * h * j / n;
        shp__setv(&m, base + j * k + i, c[0], c[1], c[2]);
      }
    for (j = 0; j < n; j++)
      for (i = 0; i < n; i++) {
        int q = base + j * k + i;
        if (s > 0) shp__quad(&p, q, q + 1, q + k + 1, q + k);
        else shp__quad(&p, q, q + k, q + k + 1, q + 1);
      }
  }
  return m;
}

/* Apply a column-major 4x4 matrix to every position (with a homogeneous divide when the
   bottom row is not (0,0,0,1)). A mirroring matrix (negative determinant) flips the
   orientation; the caller must then flip the triangles (shp_flip). */
SHP__FN void shp_transform(shp_mesh *m, const float mat[16]) {
  int i;
  if (!m || !m->pos || !mat) return;
  for (i = 0; i < m->vcount; i++) {
    double x = m->pos[3 * i], y = m->pos[3 * i + 1], z = m->pos[3 * i + 2];
    double X = mat[0] * x + mat[4] * y + mat[8] * z + mat[12];
    double Y = mat[1] * x + mat[5] * y + mat[9] * z + mat[13];
    double Z = mat[2] * x + mat[6] * y + mat[10] * z + mat[14];
    double W = mat[3] * x + mat[7] * y + mat[11] * z + mat[15];
    if (W != 1.0 && W != 0.0) {
      X /= W;
      Y /= W;
      Z /= W;
    }
    shp__setv(m, i, X, Y, Z);
  }
}

/* Reverse the winding of every triangle (turns a hull inside out). */
SHP__FN void shp_flip(shp_mesh *m) {
  int i;
  if (!m || !m->idx) return;
  for (i = 0; i + 2 < m->icount; i += 3) {
    unsigned t = m->idx[i + 1];
    m->idx[i + 1] = m->idx[i + 2];
    m->idx[i + 2] = t;
  }
}

/* Flat-shaded vertex stream for an engine's opaque pass: for every triangle corner its
   position (3 floats) and the triangle's normal (3 floats), 6 floats a corner, 18 a
   triangle, m->icount corners in all. With model == NULL the normal is the unnormalised
   object-space cross product (b-a) x (c-a); with a model matrix it is that normal carried
   by the matrix's upper 3x3 and normalised (world space, for rigid and uniform-scale
   models). Returns a malloc'd array (free() it), NULL on allocation failure or no mesh. */
SHP__FN float *shp_flat_vertices(const shp_mesh *m, const float *model) {
  float *v;
  int t, k;
  if (!m || !m->pos || !m->idx || m->icount < 3) return NULL;
  v = (float *)malloc(sizeof(float) * 6 * (size_t)m->icount);
  if (!v) return NULL;
  for (t = 0; t < m->icount / 3; ++t) {
    const float *p[3];
    float e1[3], e2[3], n[3];
    for (k = 0; k < 3; ++k) p[k] = m->pos + 3 * m->idx[3 * t + k];
    for (k = 0; k < 3; ++k) e1[k] = p[1][k] - p[0][k], e2[k] = p[2][k] - p[0][k];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    if (model) {
      float w[3], l;
      for (k = 0; k < 3; ++k) w[k] = model[k] * n[0] + model[4 + k] * n[1] + model[8 + k] * n[2];
      l = sqrtf(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) + 1e-20f;
      for (k = 0; k < 3; ++k) n[k] = w[k] / l;
    }
    for (k = 0; k < 3; ++k) {
      memcpy(v + 18 * t + 6 * k, p[k], 3 * sizeof(float));
      memcpy(v + 18 * t + 6 * k + 3, n, 3 * sizeof(float));
    }
  }
  return v;
}

/* Append b to a (vertices and re-based indices). Returns 1 on success, 0 on allocation
   failure (a is left unchanged). Handy for building one mesh out of several pieces. */
SHP__FN int shp_append(shp_mesh *a, const shp_mesh *b) {
  float *pos;
  unsigned *idx;
  int i;
  if (!a || !b || b->vcount <= 0) return 1;
  if ((double)a->vcount + b->vcount > SHP__MAXCOUNT || (double)a->icount + b->icount > SHP__MAXCOUNT)
    return 0;
  pos = (float *)malloc(((size_t)a->vcount + (size_t)b->vcount) * 3 * sizeof(float));
  idx = (unsigned *)malloc(((size_t)a->icount + (size_t)b->icount + 1) * sizeof(unsigned));
  if (!pos || !idx) {
    free(pos);
    free(idx);
    return 0;
  }
  if (a->vcount) memcpy(pos, a->pos, (size_t)a->vcount * 3 * sizeof(float));
  memcpy(pos + 3 * a->vcount, b->pos, (size_t)b->vcount * 3 * sizeof(float));
  if (a->icount) memcpy(idx, a->idx, (size_t)a->icount * sizeof(unsigned));
  for (i = 0; i < b->icount; i++) idx[a->icount + i] = b->idx[i] + (unsigned)a->vcount;
  free(a->pos);
  free(a->idx);
  a->pos = pos;
  a->idx = idx;
  a->vcount += b->vcount;
  a->icount += b->icount;
  return 1;
}

/* ---- small column-major matrix helpers (m[col*4+row]) ---- */

SHP__FN void shp_mat_identity(float m[16]) {
  int i;
  for (i = 0; i < 16; i++) m[i] = (i % 5 == 0) ? 1.0f : 0.0f;
}

SHP__FN void shp_mat_translate(float m[16], float x, float y, float z) {
  shp_mat_identity(m);
  m[12] = x;
  m[13] = y;
  m[14] = z;
}

SHP__FN void shp_mat_scale(float m[16], float x, float y, float z) {
  shp_mat_identity(m);
  m[0] = x;
  m[5] = y;
  m[10] = z;
}

/* rotation by angle_deg (counter-clockwise looking down the axis towards the origin)
   about axis (x,y,z), which need not be unit length */
SHP__FN void shp_mat_rotate(float m[16], float angle_deg, float x, float y, float z) {
  double l = sqrt((double)x * x + (double)y * y + (double)z * z), a = angle_deg * SHP__PI / 180.0;
  double c = cos(a), s = sin(a), t = 1.0 - c, X, Y, Z;
  shp_mat_identity(m);
  if (!(l > 0)) return;
  X = x / l;
  Y = y / l;
  Z = z / l;
  m[0] = (float)(t * X * X + c);
  m[1] = (float)(t * X * Y + s * Z);
  m[2] = (float)(t * X * Z - s * Y);
  m[4] = (float)(t * X * Y - s * Z);
  m[5] = (float)(t * Y * Y + c);
  m[6] = (float)(t * Y * Z + s * X);
  m[8] = (float)(t * X * Z + s * Y);
  m[9] = (float)(t * Y * Z - s * X);
  m[10] = (float)(t * Z * Z + c);
}

/* out = a * b (apply b first, then a); out may alias a or b */
SHP__FN void shp_mat_mul(float out[16], const float a[16], const float b[16]) {
  float r[16];
  int c, rr, k;
  for (c = 0; c < 4; c++)
    for (rr = 0; rr < 4; rr++) {
      double s = 0;
      for (k = 0; k < 4; k++) s += (double)a[k * 4 + rr] * b[c * 4 + k];
      r[c * 4 + rr] = (float)s;
    }
  memcpy(out, r, sizeof r);
}

#endif /* SHAPES_H */
