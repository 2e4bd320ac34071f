/* raycast.h - independent double-precision ground truth for fogvol tests (header-only,
 * C99 / C++11).
 *
 * Camera: OpenGL conventions, right-handed, the camera looks down its local -z. Matrices are
 * column-major float[16] (m[col*4+row]) as glUniformMatrix4fv(transpose=false).
 *
 * Pixels: pixel (px,py) with py = 0 the BOTTOM row; its centre sample is (px+0.5, py+0.5).
 * The ray for sample position (sx,sy) (in pixels) starts at the eye with direction
 *   dir = forward + x*tan(fovy/2)*aspect*right + y*tan(fovy/2)*up,
 *   x = sx/width*2-1, y = sy/height*2-1, |forward| = 1,
 * so the ray parameter t EQUALS view-space depth w (distance to the camera plane along the
 * view axis), i.e. the clip-space w of gluPerspective.
 *
 * Usage:
 *   rc_object o[2] = {...};         // pos/idx are only read during rc_scene_init
 *   rc_scene sc;
 *   if (!rc_scene_init(&sc, o, 2)) fail();
 *   rc_result r = rc_trace(&sc, &cam, px + 0.5, py + 0.5);
 *   if (rc_interior(&sc, &cam, px, py)) compare(r.thickness, rendered);
 *   rc_scene_free(&sc);
 *
 * Ground truth (per volume object, sign != 0): all crossings of the ray's whole line
 * (t from -inf to +inf) with the object's world-space triangles (vertices transformed by the
 * model matrix in double), classified entering (dot(n,dir) < 0, n = (b-a)x(c-a)) or exiting.
 * Walking them in t order from winding 0 at t = -inf (+1 entering, -1 exiting), the winding
 * count itself (NOT count > 0: overlapping parts of one mesh count twice) is integrated over
 * t in [znear, min(zfar, opaque_w)]; thickness = sum over volumes of sign * integral.
 *
 * Ties (a ray exactly through a shared edge or vertex) are resolved EXACTLY rather than by
 * an epsilon + de-duplication: the ray-triangle test is the watertight ray-space test of
 * Woop/Benthin/Wald (2013) in double, with edge functions evaluated antisymmetrically and
 * zeros broken by simulation of simplicity. A ray through an edge or vertex is thus counted
 * like a nearby generic ray: each surface crossing exactly once, no gaps, no double hits,
 * also at vertices whose fan mixes front- and back-facing triangles (where "merge hits of
 * the same class at equal t" gets the winding wrong). Grazing a fold gives an enter/exit
 * pair at the same t (zero weight in the integral).
 *
 * Occluders (sign == 0) are two-sided; opaque_w is their nearest crossing with t >= znear.
 *
 * Signature: FNV-1a hash of, per occluder, whether it is hit in [znear, zfar) and which
 * occluder is nearest (if before zfar); per volume, the number of crossings in [znear, zfar),
 * how many of them lie in front of opaque_w, and their entering/exiting sequence.
 */
#ifndef RAYCAST_H
#define RAYCAST_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The ground truth is the tests' oracle, not the code under test: in the sanitizer builds it runs
 * uninstrumented (ASan and UBSan made it most of those programs' time), but in its own self-test
 * (raycast_selftest_asan_ubsan defines RC_SANITIZE). */
#if defined(__SANITIZE_ADDRESS__) && !defined(RC_SANITIZE) && (defined(__GNUC__) || defined(__clang__))
#define RC__FN static inline __attribute__((no_sanitize("address", "undefined", "float-cast-overflow")))
#else
#define RC__FN static inline
#endif
#define RC__PI 3.14159265358979323846
#define RC__LEAF 4

typedef struct rc_camera {
  double eye[3], target[3], up[3];
  double fovy_deg, aspect, znear, zfar;
  int width, height; /* viewport in pixels */
} rc_camera;

typedef struct rc_object {
  const float *pos;
  int vcount;
  const unsigned *idx;
  int icount;
  float model[16]; /* column-major object->world */
  int sign;        /* +1 positive volume, -1 negative volume, 0 = opaque occluder (two-sided) */
} rc_object;

typedef struct rc_result {
  double thickness;   /* sum of sign * integrated winding, world units of view depth w */
  double opaque_w;    /* nearest occluder hit with w >= znear (any zfar), or +INFINITY */
  int faces_front;    /* volume triangles crossed facing the camera, znear <= w < zfar (behind
                         opaque_w too); on exact edge/vertex ties those of a nearby generic ray */
  int faces_back;     /* volume triangles crossed facing away, znear <= w < zfar */
  unsigned signature; /* hash of the hit topology: equal signatures = same topology */
} rc_result;

/* ---- scene (world space, built once) ---- */

typedef struct rc__tri {
  double v[3][3]; /* world-space vertices */
} rc__tri;

typedef struct rc__node {
  double lo[3], hi[3];
  int first; /* leaf: first triangle; inner node: index of the left child (right = first+1) */
  int count; /* leaf: number of triangles (> 0); inner node: 0 */
} rc__node;

typedef struct rc_scene_object {
  int sign;
  int tcount;
  rc__tri *tris;   /* world-space triangles in BVH order */
  rc__node *nodes; /* BVH, node 0 is the root; NULL when tcount == 0 */
  int ncount;
  double bs_center[3], bs_radius; /* world-space bounding sphere */
} rc_scene_object;

/* rc_interior's samples: the signature of each sample point traced for one camera (a pixel's corners
   and its neighbours' centres are its neighbours' samples too, so a whole image traces each point
   once instead of 13 times). Open addressing; slots of other generations are empty (a new camera
   starts a generation). */
typedef struct rc__memo {
  rc_camera cam;
  double *key; /* sx, sy per slot */
  unsigned *sig, *gen, cur;
  int cap, n;
} rc__memo;

typedef struct rc_scene {
  rc_scene_object *objs;
  int count;
  rc__memo *memo; /* rc_interior's, made on its first call (NULL: none yet) */
} rc_scene;

/* ---- small vector helpers ---- */

RC__FN double rc__dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

RC__FN void rc__cross(const double a[3], const double b[3], double o[3]) {
  double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
  o[0] = x;
  o[1] = y;
  o[2] = z;
}

RC__FN void rc__sub(const double a[3], const double b[3], double o[3]) {
  o[0] = a[0] - b[0];
  o[1] = a[1] - b[1];
  o[2] = a[2] - b[2];
}

RC__FN void rc__normalize(double a[3]) {
  double l = sqrt(rc__dot(a, a));
  if (l > 0) {
    a[0] /= l;
    a[1] /= l;
    a[2] /= l;
  }
}

/* ---- camera ---- */

/* orthonormal camera basis: f = forward (unit), s = right, u = true up (as gluLookAt) */
RC__FN void rc_camera_basis(const rc_camera *c, double f[3], double s[3], double u[3]) {
  rc__sub(c->target, c->eye, f);
  rc__normalize(f);
  rc__cross(f, c->up, s);
  rc__normalize(s);
  rc__cross(s, f, u);
}

/* gluLookAt + gluPerspective equivalents, column-major */
RC__FN void rc_camera_matrices(const rc_camera *c, float view[16], float proj[16]) {
  double f[3], s[3], u[3], t, n = c->znear, fa = c->zfar;
  int i;
  rc_camera_basis(c, f, s, u);
  for (i = 0; i < 16; i++) view[i] = proj[i] = 0.0f;
  for (i = 0; i < 3; i++) {
    view[i * 4 + 0] = (float)s[i];
    view[i * 4 + 1] = (float)u[i];
    view[i * 4 + 2] = (float)-f[i];
  }
  view[12] = (float)-rc__dot(s, c->eye);
  view[13] = (float)-rc__dot(u, c->eye);
  view[14] = (float)rc__dot(f, c->eye);
  view[15] = 1.0f;
  t = 1.0 / tan(c->fovy_deg * RC__PI / 360.0);
  proj[0] = (float)(t / c->aspect);
  proj[5] = (float)t;
  proj[10] = (float)((fa + n) / (n - fa));
  proj[11] = -1.0f;
  proj[14] = (float)(2.0 * fa * n / (n - fa));
}

/* ray for sample position (sx,sy) in pixels (py = 0 bottom row, centre = +0.5) */
RC__FN void rc_camera_ray(const rc_camera *c, double sx, double sy, double org[3], double dir[3]) {
  double f[3], s[3], u[3], th = tan(c->fovy_deg * RC__PI / 360.0);
  double x = sx / c->width * 2.0 - 1.0, y = sy / c->height * 2.0 - 1.0;
  int i;
  rc_camera_basis(c, f, s, u);
  for (i = 0; i < 3; i++) {
    org[i] = c->eye[i];
    dir[i] = f[i] + x * th * c->aspect * s[i] + y * th * u[i];
  }
}

/* ---- scene construction ---- */

RC__FN void rc_scene_free(rc_scene *sc) {
  int i;
  if (!sc) return;
  for (i = 0; i < sc->count; i++) {
    free(sc->objs[i].tris);
    free(sc->objs[i].nodes);
  }
  free(sc->objs);
  if (sc->memo) {
    free(sc->memo->key);
    free(sc->memo->sig);
    free(sc->memo->gen);
    free(sc->memo);
  }
  memset(sc, 0, sizeof *sc);
}

typedef struct rc__build {
  const double *tlo, *thi, *cen; /* per triangle box and centroid (3 doubles each) */
  int *perm;
  rc__node *nodes;
  int nnodes;
  double pad;
} rc__build;

/* quickselect: reorder perm[lo..hi] so that perm[k] has the k-th smallest key on axis */
RC__FN void rc__select(int *perm, const double *cen, int axis, int lo, int hi, int k) {
  while (hi > lo) {
    double pivot = cen[perm[lo + (hi - lo) / 2] * 3 + axis];
    int i = lo, j = hi;
    while (i <= j) {
      while (cen[perm[i] * 3 + axis] < pivot) i++;
      while (cen[perm[j] * 3 + axis] > pivot) j--;
      if (i <= j) {
        int t = perm[i];
        perm[i] = perm[j];
        perm[j] = t;
        i++;
        j--;
      }
    }
    if (k <= j)
      hi = j;
    else if (k >= i)
      lo = i;
    else
      break;
  }
}

RC__FN void rc__build_node(rc__build *b, int node, int first, int count) {
  rc__node *n = &b->nodes[node];
  double clo[3], chi[3];
  int i, k, axis, mid, child;
  for (k = 0; k < 3; k++) {
    n->lo[k] = clo[k] = INFINITY;
    n->hi[k] = chi[k] = -INFINITY;
  }
  for (i = first; i < first + count; i++) {
    int t = b->perm[i];
    for (k = 0; k < 3; k++) {
      if (b->tlo[3 * t + k] < n->lo[k]) n->lo[k] = b->tlo[3 * t + k];
      if (b->thi[3 * t + k] > n->hi[k]) n->hi[k] = b->thi[3 * t + k];
      if (b->cen[3 * t + k] < clo[k]) clo[k] = b->cen[3 * t + k];
      if (b->cen[3 * t + k] > chi[k]) chi[k] = b->cen[3 * t + k];
    }
  }
  for (k = 0; k < 3; k++) {
    n->lo[k] -= b->pad;
    n->hi[k] += b->pad;
  }
  axis = 0;
  for (k = 1; k < 3; k++)
    if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
  if (count <= RC__LEAF || !(chi[axis] > clo[axis])) {
    n->first = first;
    n->count = count;
    return;
  }
  mid = first + count / 2;
  rc__select(b->perm, b->cen, axis, first, first + count - 1, mid);
  child = b->nnodes;
  b->nnodes += 2;
  n->first = child;
  n->count = 0;
  rc__build_node(b, child, first, mid - first);
  rc__build_node(b, child + 1, mid, first + count - mid);
}

RC__FN int rc__object_init(rc_scene_object *so, const rc_object *o) {
  double *wp = NULL, *tlo = NULL, *thi = NULL, *cen = NULL, scale = 0;
  int *perm = NULL;
  int i, k, nt, ok = 0;
  const float *m = o->model;
  memset(so, 0, sizeof *so);
  so->sign = o->sign;
  if (o->icount < 0 || o->vcount < 0) return 0;
  nt = o->icount / 3;
  if (nt == 0) return 1;
  if (!o->pos || !o->idx) return 0;
  for (i = 0; i < nt * 3; i++)
    if (o->idx[i] >= (unsigned)o->vcount) return 0;
  wp = (double *)malloc((size_t)o->vcount * 3 * sizeof(double));
  tlo = (double *)malloc((size_t)nt * 3 * sizeof(double));
  thi = (double *)malloc((size_t)nt * 3 * sizeof(double));
  cen = (double *)malloc((size_t)nt * 3 * sizeof(double));
  perm = (int *)malloc((size_t)nt * sizeof(int));
  so->tris = (rc__tri *)malloc((size_t)nt * sizeof(rc__tri));
  so->nodes = (rc__node *)malloc((size_t)nt * 2 * sizeof(rc__node));
  if (!wp || !tlo || !thi || !cen || !perm || !so->tris || !so->nodes) goto done;
  for (i = 0; i < o->vcount; i++) {
    double x = o->pos[3 * i], y = o->pos[3 * i + 1], z = o->pos[3 * i + 2];
    double X = m[0] * (double)x + m[4] * (double)y + m[8] * (double)z + m[12];
    double Y = m[1] * (double)x + m[5] * (double)y + m[9] * (double)z + m[13];
    double Z = m[2] * (double)x + m[6] * (double)y + m[10] * (double)z + m[14];
    double W = m[3] * (double)x + m[7] * (double)y + m[11] * (double)z + m[15];
    if (W != 1.0 && W != 0.0) {
      X /= W;
      Y /= W;
      Z /= W;
    }
    wp[3 * i] = X;
    wp[3 * i + 1] = Y;
    wp[3 * i + 2] = Z;
  }
  for (i = 0; i < nt; i++) {
    const double *a = wp + 3 * o->idx[3 * i], *b = wp + 3 * o->idx[3 * i + 1], *c = wp + 3 * o->idx[3 * i + 2];
    for (k = 0; k < 3; k++) {
      double lo = a[k], hi = a[k];
      if (b[k] < lo) lo = b[k];
      if (c[k] < lo) lo = c[k];
      if (b[k] > hi) hi = b[k];
      if (c[k] > hi) hi = c[k];
      tlo[3 * i + k] = lo;
      thi[3 * i + k] = hi;
      cen[3 * i + k] = (a[k] + b[k] + c[k]) / 3.0;
      if (fabs(lo) > scale) scale = fabs(lo);
      if (fabs(hi) > scale) scale = fabs(hi);
    }
    perm[i] = i;
  }
  {
    rc__build b;
    b.tlo = tlo;
    b.thi = thi;
    b.cen = cen;
    b.perm = perm;
    b.nodes = so->nodes;
    b.nnodes = 1;
    b.pad = 1e-9 * (scale + 1e-300);
    rc__build_node(&b, 0, 0, nt);
    so->ncount = b.nnodes;
  }
  for (i = 0; i < nt; i++) {
    int t = perm[i];
    const double *a = wp + 3 * o->idx[3 * t], *b = wp + 3 * o->idx[3 * t + 1], *c = wp + 3 * o->idx[3 * t + 2];
    rc__tri *tr = &so->tris[i];
    for (k = 0; k < 3; k++) {
      tr->v[0][k] = a[k];
      tr->v[1][k] = b[k];
      tr->v[2][k] = c[k];
    }
  }
  so->tcount = nt;
  /* bounding sphere: centre of the root box, radius to the farthest used vertex */
  {
    const rc__node *r = &so->nodes[0];
    double r2 = 0;
    for (k = 0; k < 3; k++) so->bs_center[k] = 0.5 * (r->lo[k] + r->hi[k]);
    for (i = 0; i < nt * 3; i++) {
      double d[3], l2;
      rc__sub(wp + 3 * o->idx[i], so->bs_center, d);
      l2 = rc__dot(d, d);
      if (l2 > r2) r2 = l2;
    }
    so->bs_radius = sqrt(r2) * (1.0 + 1e-9) + 2e-9 * scale;
  }
  ok = 1;
done:
  free(wp);
  free(tlo);
  free(thi);
  free(cen);
  free(perm);
  if (!ok) {
    free(so->tris);
    free(so->nodes);
    so->tris = NULL;
    so->nodes = NULL;
  }
  return ok;
}

/* Build the world-space scene (vertices transformed by the model matrices in double, BVH
   per object). The objects' pos/idx arrays are not referenced afterwards.
   Returns 1 on success, 0 on failure (allocation, index out of range); on failure *sc is
   zeroed and needs no rc_scene_free. */
RC__FN int rc_scene_init(rc_scene *sc, const rc_object *objs, int count) {
  int i;
  if (!sc) return 0;
  memset(sc, 0, sizeof *sc);
  if (count < 0 || (count > 0 && !objs)) return 0;
  if (count == 0) return 1;
  sc->objs = (rc_scene_object *)calloc((size_t)count, sizeof(rc_scene_object));
  if (!sc->objs) return 0;
  sc->count = count;
  for (i = 0; i < count; i++)
    if (!rc__object_init(&sc->objs[i], &objs[i])) {
      rc_scene_free(sc);
      return 0;
    }
  return 1;
}

/* ---- ray queries ---- */

typedef struct rc__hit {
  double t;
  int enter; /* 1: dot(n,dir) < 0 (entering / front face), 0: exiting / back face */
} rc__hit;

typedef struct rc__hitbuf {
  rc__hit *h;
  int n, cap, oom;
  rc__hit local[128];
} rc__hitbuf;

RC__FN void rc__hitbuf_init(rc__hitbuf *b) {
  b->h = b->local;
  b->n = 0;
  b->cap = (int)(sizeof b->local / sizeof b->local[0]);
  b->oom = 0;
}

RC__FN void rc__hitbuf_free(rc__hitbuf *b) {
  if (b->h != b->local) free(b->h);
  b->h = b->local;
}

RC__FN void rc__hitbuf_push(rc__hitbuf *b, double t, int enter) {
  if (b->n == b->cap) {
    rc__hit *nh;
    if (b->cap > 0x3fffffff / (int)sizeof(rc__hit)) {
      b->oom = 1;
      return;
    }
    nh = (rc__hit *)malloc((size_t)b->cap * 2 * sizeof(rc__hit));
    if (!nh) {
      b->oom = 1;
      return;
    }
    memcpy(nh, b->h, (size_t)b->n * sizeof(rc__hit));
    if (b->h != b->local) free(b->h);
    b->h = nh;
    b->cap *= 2;
  }
  b->h[b->n].t = t;
  b->h[b->n].enter = enter;
  b->n++;
}

/* line (o + t d) against the slab box, t restricted to [tmin, tmax] */
RC__FN int rc__box_hit(const rc__node *n, const double o[3], const double d[3], double tmin, double tmax) {
  int k;
  for (k = 0; k < 3; k++) {
    if (d[k] == 0.0) {
      if (o[k] < n->lo[k] || o[k] > n->hi[k]) return 0;
    } else {
      double inv = 1.0 / d[k], t0 = (n->lo[k] - o[k]) * inv, t1 = (n->hi[k] - o[k]) * inv;
      if (t0 > t1) {
        double t = t0;
        t0 = t1;
        t1 = t;
      }
      if (t0 > tmin) tmin = t0;
      if (t1 < tmax) tmax = t1;
      if (tmin > tmax) return 0;
    }
  }
  return 1;
}

/* Ray in "ray space" (Woop, Benthin, Wald 2013): translate to the origin, permute so that
   the dominant direction axis is z, shear so that the ray is the +z axis. Every vertex is
   mapped by the same deterministic function, so shared edges and vertices project to
   bit-identical 2D points in all the triangles that use them. */
typedef struct rc__ray {
  double o[3], d[3];
  int kx, ky, kz;
  double sx, sy, sz;
} rc__ray;

RC__FN void rc__ray_setup(rc__ray *r, const double o[3], const double d[3]) {
  int k;
  for (k = 0; k < 3; k++) {
    r->o[k] = o[k];
    r->d[k] = d[k];
  }
  r->kz = 0;
  if (fabs(d[1]) > fabs(d[r->kz])) r->kz = 1;
  if (fabs(d[2]) > fabs(d[r->kz])) r->kz = 2;
  r->kx = (r->kz + 1) % 3;
  r->ky = (r->kx + 1) % 3;
  if (d[r->kz] < 0) { /* keep the permuted frame right-handed w.r.t. the ray direction */
    k = r->kx;
    r->kx = r->ky;
    r->ky = k;
  }
  r->sx = d[r->kx] / d[r->kz];
  r->sy = d[r->ky] / d[r->kz];
  r->sz = 1.0 / d[r->kz];
}

/* vertex -> ray space: (x, y) in the plane across the ray, z = ray parameter t of its plane */
RC__FN void rc__project(const rc__ray *r, const double v[3], double p[3]) {
  double ax = v[r->kx] - r->o[r->kx], ay = v[r->ky] - r->o[r->ky], az = v[r->kz] - r->o[r->kz];
  p[0] = ax - r->sx * az;
  p[1] = ay - r->sy * az;
  p[2] = r->sz * az;
}

/* 2D edge function of the origin w.r.t. edge P->Q (> 0: origin left of P->Q), with an exact,
   consistent tie-break: the value is computed for the lexicographically ordered endpoints
   (so the two triangles sharing an edge get exactly opposite values, whatever the compiler
   does with FMA contraction), and a zero is resolved by simulation of simplicity, as if the
   origin sat at (eps, eps^2): E' = E + eps*(Py - Qy) + eps^2*(Qx - Px). A point on an edge
   or vertex is therefore inside exactly the triangles that contain a nearby generic point,
   so every surface crossing is counted exactly once (no gaps, no double hits). */
RC__FN double rc__edge(const double *P, const double *Q, int *sgn) {
  int flip = P[0] > Q[0] || (P[0] == Q[0] && P[1] > Q[1]);
  const double *a = flip ? Q : P, *b = flip ? P : Q;
  double e = a[0] * b[1] - a[1] * b[0];
  int s;
  if (e > 0)
    s = 1;
  else if (e < 0)
    s = -1;
  else {
    double dy = a[1] - b[1], dx = b[0] - a[0];
    s = dy > 0 ? 1 : dy < 0 ? -1 : dx > 0 ? 1 : dx < 0 ? -1 : 0;
  }
  *sgn = flip ? -s : s;
  return flip ? -e : e;
}

/* all crossings of the line (t in [tmin,tmax]) with the object's triangles */
RC__FN void rc__object_hits(const rc_scene_object *so, const rc__ray *ray, double tmin, double tmax,
                            rc__hitbuf *buf) {
  int stack[128], sp = 0;
  const double *o = ray->o, *d = ray->d;
  if (so->tcount == 0) return;
  { /* bounding sphere reject: distance from centre to the line */
    double oc[3], dd = rc__dot(d, d), s, q[3], dist2;
    rc__sub(so->bs_center, o, oc);
    s = rc__dot(oc, d) / dd;
    q[0] = oc[0] - s * d[0];
    q[1] = oc[1] - s * d[1];
    q[2] = oc[2] - s * d[2];
    dist2 = rc__dot(q, q);
    if (dist2 > so->bs_radius * so->bs_radius) return;
  }
  stack[sp++] = 0;
  while (sp > 0) {
    const rc__node *n = &so->nodes[stack[--sp]];
    if (!rc__box_hit(n, o, d, tmin, tmax)) continue;
    if (n->count == 0) {
      if (sp + 2 > (int)(sizeof stack / sizeof stack[0])) { /* cannot happen: depth <= 32 */
        buf->oom = 1;
        return;
      }
      stack[sp++] = n->first;
      stack[sp++] = n->first + 1;
    } else {
      int i;
      for (i = n->first; i < n->first + n->count; i++) {
        const rc__tri *tr = &so->tris[i];
        double A[3], B[3], C[3], u, v, w, det, t;
        int su, sv, sw;
        rc__project(ray, tr->v[0], A);
        rc__project(ray, tr->v[1], B);
        rc__project(ray, tr->v[2], C);
        u = rc__edge(B, C, &su);
        v = rc__edge(C, A, &sv);
        w = rc__edge(A, B, &sw);
        if (su == 0 || su != sv || su != sw) continue;
        det = u + v + w;
        if (det == 0.0) continue;
        t = (u * A[2] + v * B[2] + w * C[2]) / det;
        if (t < tmin || t > tmax) continue;
        /* counter-clockwise around the +z ray axis = normal along the ray = exiting */
        rc__hitbuf_push(buf, t, su < 0);
      }
    }
  }
}

RC__FN int rc__hit_cmp(const void *a, const void *b) {
  const rc__hit *x = (const rc__hit *)a, *y = (const rc__hit *)b;
  if (x->t < y->t) return -1;
  if (x->t > y->t) return 1;
  return y->enter - x->enter; /* entering first on exact ties (irrelevant for the integral) */
}

/* sort by t (crossings are exact, nothing to merge) */
RC__FN void rc__sort(rc__hitbuf *b) {
  int i, j;
  if (b->n > 32)
    qsort(b->h, (size_t)b->n, sizeof(rc__hit), rc__hit_cmp);
  else
    for (i = 1; i < b->n; i++) {
      rc__hit h = b->h[i];
      for (j = i; j > 0 && rc__hit_cmp(&b->h[j - 1], &h) > 0; j--) b->h[j] = b->h[j - 1];
      b->h[j] = h;
    }
}

RC__FN unsigned rc__mix(unsigned h, unsigned v) {
  int i;
  for (i = 0; i < 4; i++) {
    h ^= (v >> (8 * i)) & 0xffu;
    h *= 16777619u; /* FNV-1a */
  }
  return h;
}

/* Pass 1 of a trace: the nearest occluder crossing with t >= zn (INFINITY if none) and its
   object index in *nearest; with h, each occluder's index and whether it is crossed before zf
   are mixed into *h (the signature). */
RC__FN double rc__occluders(const rc_scene *sc, const rc__ray *ray, double zn, double zf, rc__hitbuf *buf,
                            int *nearest, unsigned *h, int *oom) {
  double opaque = INFINITY;
  int i, k;
  for (i = 0; i < sc->count; i++) {
    int inrange = 0;
    if (sc->objs[i].sign != 0) continue;
    buf->n = 0;
    rc__object_hits(&sc->objs[i], ray, zn, INFINITY, buf);
    *oom |= buf->oom;
    for (k = 0; k < buf->n; k++) {
      if (buf->h[k].t < zf) inrange = 1;
      if (buf->h[k].t < opaque) {
        opaque = buf->h[k].t;
        *nearest = i;
      }
    }
    if (h) {
      *h = rc__mix(*h, (unsigned)i);
      *h = rc__mix(*h, (unsigned)inrange);
    }
  }
  return opaque;
}

/* Trace the sample (sx,sy) (pixel units, see top of file). On allocation failure the
   thickness is NaN. */
RC__FN rc_result rc_trace(const rc_scene *sc, const rc_camera *cam, double sx, double sy) {
  rc_result r;
  rc__hitbuf buf;
  rc__ray ray;
  double o[3], d[3], zn = cam->znear, zf = cam->zfar, end, th = 0.0;
  unsigned h = 2166136261u;
  int i, k, nearest = -1, oom = 0;
  memset(&r, 0, sizeof r);
  r.opaque_w = INFINITY;
  rc_camera_ray(cam, sx, sy, o, d);
  rc__ray_setup(&ray, o, d);
  rc__hitbuf_init(&buf);
  r.opaque_w = rc__occluders(sc, &ray, zn, zf, &buf, &nearest, &h, &oom); /* pass 1: occluders (two-sided) */
  end = r.opaque_w < zf ? r.opaque_w : zf;
  h = rc__mix(h, (unsigned)(r.opaque_w < zf ? nearest : -1));
  /* pass 2: volumes, whole line */
  for (i = 0; i < sc->count; i++) {
    const rc_scene_object *so = &sc->objs[i];
    double integral = 0.0, prev = zn;
    int cnt = 0, nin = 0, nfront = 0;
    unsigned cls = 2166136261u;
    if (so->sign == 0) continue;
    buf.n = 0;
    rc__object_hits(so, &ray, -INFINITY, INFINITY, &buf);
    oom |= buf.oom;
    rc__sort(&buf);
    for (k = 0; k < buf.n; k++) {
      double t = buf.h[k].t, c = t;
      if (end > zn) {
        if (c < zn) c = zn;
        if (c > end) c = end;
        if (c > prev) {
          integral += cnt * (c - prev);
          prev = c;
        }
      }
      cnt += buf.h[k].enter ? 1 : -1;
      if (t >= zn && t < zf) {
        nin++;
        if (buf.h[k].enter)
          r.faces_front++;
        else
          r.faces_back++;
        if (t < r.opaque_w) nfront++;
        cls = rc__mix(cls, (unsigned)buf.h[k].enter);
      }
    }
    if (cnt != 0 && end > prev) integral += cnt * (end - prev); /* open mesh only */
    th += so->sign * integral;
    h = rc__mix(h, (unsigned)i);
    h = rc__mix(h, (unsigned)nin);
    h = rc__mix(h, (unsigned)nfront);
    h = rc__mix(h, cls);
  }
  rc__hitbuf_free(&buf);
  r.thickness = oom ? NAN : th;
  r.signature = h;
  return r;
}

/* The chords of sample (sx,sy): per volume object, each maximal interval of view depth w in
   [znear, min(zfar, opaque_w)] where that object's winding count is positive, as pairs
   (ab[2k], ab[2k+1]) with obj[k] the object's index (obj may be NULL). Returns the count
   (<= cap; -1 on allocation failure). */
RC__FN int rc_chords(const rc_scene *sc, const rc_camera *cam, double sx, double sy, double *ab, int *obj, int cap) {
  rc__hitbuf buf;
  rc__ray ray;
  double o[3], d[3], zn = cam->znear, zf = cam->zfar, opaque, end;
  int i, k, n = 0, oom = 0, nearest = -1;
  rc_camera_ray(cam, sx, sy, o, d);
  rc__ray_setup(&ray, o, d);
  rc__hitbuf_init(&buf);
  opaque = rc__occluders(sc, &ray, zn, zf, &buf, &nearest, NULL, &oom);
  end = opaque < zf ? opaque : zf;
  for (i = 0; i < sc->count; i++) {
    int cnt = 0;
    double start = 0.0;
    if (sc->objs[i].sign == 0) continue;
    buf.n = 0;
    rc__object_hits(&sc->objs[i], &ray, -INFINITY, INFINITY, &buf);
    oom |= buf.oom;
    rc__sort(&buf);
    for (k = 0; k < buf.n; k++) {
      int was = cnt > 0;
      cnt += buf.h[k].enter ? 1 : -1;
      if (!was && cnt > 0) start = buf.h[k].t;
      if (was && cnt <= 0) {
        double a = start < zn ? zn : start, b = buf.h[k].t > end ? end : buf.h[k].t;
        if (b > a && n < cap) {
          ab[2 * n] = a;
          ab[2 * n + 1] = b;
          if (obj) obj[n] = i;
          n++;
        }
      }
    }
  }
  rc__hitbuf_free(&buf);
  return oom ? -1 : n;
}

/* The view depths w of sample (sx,sy) that a rasteriser's faces produce: the nearest occluder
   crossing (if before zfar) and every volume crossing in [znear, min(zfar, opaque_w)], per
   volume in t order. Returns the count (<= cap; -1 on allocation failure). */
RC__FN int rc__counted_depths(const rc_scene *sc, const rc_camera *cam, double sx, double sy, double *w, int cap) {
  rc__hitbuf buf;
  rc__ray ray;
  double o[3], d[3], zn = cam->znear, zf = cam->zfar, opaque, end;
  int i, k, n = 0, oom = 0, nearest = -1;
  rc_camera_ray(cam, sx, sy, o, d);
  rc__ray_setup(&ray, o, d);
  rc__hitbuf_init(&buf);
  opaque = rc__occluders(sc, &ray, zn, zf, &buf, &nearest, NULL, &oom);
  end = opaque < zf ? opaque : zf;
  if (opaque < zf && n < cap) w[n++] = opaque;
  for (i = 0; i < sc->count; i++) {
    if (sc->objs[i].sign == 0) continue;
    buf.n = 0;
    rc__object_hits(&sc->objs[i], &ray, zn, end, &buf);
    oom |= buf.oom;
    rc__sort(&buf);
    for (k = 0; k < buf.n && n < cap; k++) w[n++] = buf.h[k].t;
  }
  rc__hitbuf_free(&buf);
  return oom ? -1 : n;
}

/* How fast the depths of pixel (px,py)'s centre sample move with the sample position: the sum
   over the depths rc__counted_depths lists of |dw/dsx| + |dw/dsy| (view-depth units per pixel),
   by differences over 1/1024 pixel; INFINITY where the crossings change within that distance.
   A GL rasteriser snaps vertices to a grid of 2^-GL_SUBPIXEL_BITS pixels, which moves each
   face's plane by up to about that much at the sample: delta * rc_depth_slope bounds what the
   snapping adds to a thickness error (the GL spec leaves the rounding to the implementation). */
RC__FN double rc_depth_slope(const rc_scene *sc, const rc_camera *cam, int px, int py) {
  enum { CAP = 256 };
  const double eps = 1.0 / 1024.0;
  double w0[CAP], wx[CAP], wy[CAP], sum = 0.0;
  int n0 = rc__counted_depths(sc, cam, px + 0.5, py + 0.5, w0, CAP), i;
  if (n0 < 0 || n0 == CAP || rc__counted_depths(sc, cam, px + 0.5 + eps, py + 0.5, wx, CAP) != n0 ||
      rc__counted_depths(sc, cam, px + 0.5, py + 0.5 + eps, wy, CAP) != n0)
    return INFINITY;
  for (i = 0; i < n0; i++) sum += fabs(wx[i] - w0[i]) + fabs(wy[i] - w0[i]);
  return sum / eps;
}

RC__FN int rc__same_camera(const rc_camera *a, const rc_camera *b) {
  int k;
  for (k = 0; k < 3; k++)
    if (a->eye[k] != b->eye[k] || a->target[k] != b->target[k] || a->up[k] != b->up[k]) return 0;
  return a->fovy_deg == b->fovy_deg && a->aspect == b->aspect && a->znear == b->znear && a->zfar == b->zfar &&
         a->width == b->width && a->height == b->height;
}

RC__FN unsigned rc__memo_hash(double sx, double sy) {
  unsigned long long a, b;
  memcpy(&a, &sx, sizeof a);
  memcpy(&b, &sy, sizeof b);
  a ^= b * 0x9e3779b97f4a7c15ull;
  a ^= a >> 29;
  a *= 0xbf58476d1ce4e5b9ull;
  return (unsigned)(a ^ (a >> 32));
}

/* The memo's slots doubled (the live generation's entries moved over); 0: out of memory. */
RC__FN int rc__memo_grow(rc__memo *m) {
  int cap = m->cap ? 2 * m->cap : 4096, i;
  double *key = (double *)malloc(sizeof(double) * 2 * (size_t)cap);
  unsigned *sig = (unsigned *)malloc(sizeof(unsigned) * (size_t)cap), *gen = (unsigned *)calloc((size_t)cap, sizeof(unsigned));
  if (!key || !sig || !gen) {
    free(key);
    free(sig);
    free(gen);
    return 0;
  }
  for (i = 0; i < m->cap; i++)
    if (m->gen[i] == m->cur) {
      unsigned h = rc__memo_hash(m->key[2 * i], m->key[2 * i + 1]) & (unsigned)(cap - 1);
      while (gen[h] == m->cur) h = (h + 1) & (unsigned)(cap - 1);
      key[2 * h] = m->key[2 * i];
      key[2 * h + 1] = m->key[2 * i + 1];
      sig[h] = m->sig[i];
      gen[h] = m->cur;
    }
  free(m->key);
  free(m->sig);
  free(m->gen);
  m->key = key;
  m->sig = sig;
  m->gen = gen;
  m->cap = cap;
  return 1;
}

/* The signature of sample (sx,sy), traced once per camera and scene (rc_trace where no memory). */
RC__FN unsigned rc__sample_signature(const rc_scene *sc, const rc_camera *cam, double sx, double sy) {
  rc__memo *m = sc->memo;
  unsigned h, s;
  if (!m) {
    m = (rc__memo *)calloc(1, sizeof *m);
    if (!m) return rc_trace(sc, cam, sx, sy).signature;
    m->cur = 1;
    m->cam = *cam;
    ((rc_scene *)sc)->memo = m; /* the scene is the caller's (non-const) object */
  } else if (!rc__same_camera(&m->cam, cam)) {
    m->cam = *cam;
    m->n = 0;
    if (++m->cur == 0) { /* generations wrapped: clear the slots */
      if (m->gen) memset(m->gen, 0, sizeof(unsigned) * (size_t)m->cap);
      m->cur = 1;
    }
  }
  if (2 * (m->n + 1) > m->cap && !rc__memo_grow(m)) return rc_trace(sc, cam, sx, sy).signature;
  for (h = rc__memo_hash(sx, sy) & (unsigned)(m->cap - 1); m->gen[h] == m->cur; h = (h + 1) & (unsigned)(m->cap - 1))
    if (m->key[2 * h] == sx && m->key[2 * h + 1] == sy) return m->sig[h];
  s = rc_trace(sc, cam, sx, sy).signature;
  m->key[2 * h] = sx;
  m->key[2 * h + 1] = sy;
  m->sig[h] = s;
  m->gen[h] = m->cur;
  m->n++;
  return s;
}

/* 1 if pixel (px,py) is "interior": the signature at the pixel centre equals the signatures
   at the 4 pixel corners and at the 8 neighbouring pixel centres (so one-pixel silhouette
   bands, opaque/volume intersection curves and near/far-plane crossings are excluded). The
   samples' signatures are kept with the scene for the camera (the next pixel shares most of
   them); rc_scene_free frees them. */
RC__FN int rc_interior(const rc_scene *sc, const rc_camera *cam, int px, int py) {
  const double off[12][2] = {{0, 0},      {1, 0},     {0, 1},     {1, 1},    {-0.5, -0.5}, {0.5, -0.5},
                             {1.5, -0.5}, {-0.5, 0.5}, {1.5, 0.5}, {-0.5, 1.5}, {0.5, 1.5},  {1.5, 1.5}};
  unsigned s0 = rc__sample_signature(sc, cam, px + 0.5, py + 0.5);
  int i;
  for (i = 0; i < 12; i++)
    if (rc__sample_signature(sc, cam, px + off[i][0], py + off[i][1]) != s0) return 0;
  return 1;
}

#endif /* RAYCAST_H */
