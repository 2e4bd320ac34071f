/* sequence.h - any engine-input test as a sequence of frames, each frame checked against its own
 * ground truth (issue 31).
 *
 * Engines draw many frames: the camera moves into and out of the volumes, occluders come and go,
 * the window resizes, two views share a frame (split screen, mirrors), a frame is given up half
 * built. Whatever fogvol copies or caches from the engine (its depth, its O, target sizes, queries,
 * the programs a frame picks) must follow. A test states what it can vary (SQ_* bits) and gives
 * one function that draws and checks one view (the engine's part, fogvol's frame, the comparison
 * with that view's own truth); sq_run drives it through a script of frames and counts the wrong
 * pixels of every view of every frame.
 *
 *   static void my_view(void *user, const sq_view *v, sq_check *out) {
 *       camera from v->walk[...]; the engine draws into v->viewport (its occluders if v->occluders);
 *       fogvol_begin_frame with viewport v->viewport ... fogvol_end_frame;
 *       compare with the truth of this camera and viewport: out->pixels, out->wrong, out->max_err,
 *       out->bound;
 *   }
 *   sq_totals t = sq_run("name", W, H, sq_default_script, SQ_DEFAULT_FRAMES, SQ_ALL, my_view, my_cancel, user);
 *   (sq_run fails the running cmocka test when a view has a wrong pixel, after the whole sequence,
 *   so the message gives the total count and the first bad frame)
 *
 * A view: walk is the camera's place on the test's path (0: its start, outside the volumes; 1:
 * as deep inside as the test can go; the test maps it to a pose); occluders: the engine draws its
 * occluders this frame; viewport: x, y, w, h in the w x h framebuffer (the full one, a smaller one
 * at an offset, or one half of a split screen); cancelled: a frame was begun, filled with this
 * view's input and cancelled (fogvol_cancel_frame) just before, through the test's cancel function.
 * Header-only; include after <cmocka.h>. */
#ifndef FOGVOL_TESTS_SEQUENCE_H
#define FOGVOL_TESTS_SEQUENCE_H

#include <stdio.h>
#include <string.h>

#ifdef GL_SUBPIXEL_BITS /* (after a GL or GLES header) */
#include <math.h>
/* The grid the current GL context snaps vertices to, in pixels: 2^-GL_SUBPIXEL_BITS (the GL
   minimum of 4 bits where the context reports fewer; 8 on llvmpipe and NVIDIA). A sample's depths
   move by up to about that times their slope (rc_depth_slope): the tests add it to their bounds. */
static inline double snap_pixels(void)
{
    GLint bits = 0;
    glGetIntegerv(GL_SUBPIXEL_BITS, &bits);
    return ldexp(1.0, -(bits < 4 ? 4 : bits));
}
#endif

/* what a frame may change against the frame before it */
enum {
    SQ_CAMERA = 1,   /* the camera moves along the test's walk (into the volume and out) */
    SQ_OCCLUDER = 2, /* the occluders appear and disappear */
    SQ_RESIZE = 4,   /* the viewport shrinks to a rectangle at an offset and grows back */
    SQ_SPLIT = 8,    /* two views in one frame: left and right halves, each its own camera */
    SQ_CANCEL = 16,  /* a frame begun and cancelled comes in between */
    SQ_ALL = 31
};

/* one frame of a script */
typedef struct sq_step {
    double walk[2]; /* the camera of each view on the walk (view 1: split-screen frames only) */
    int occluders;  /* 1: the engine draws its occluders */
    int views;      /* 1, or 2: split screen */
    int small;      /* 1: the viewport is the smaller rectangle at an offset */
    int cancel;     /* 1: a cancelled frame comes first */
} sq_step;

/* one view of one frame, as the test's view function gets it */
typedef struct sq_view {
    int frame, view, views; /* frame index, this view's index in the frame, views in the frame */
    unsigned changes;       /* SQ_* bits: what differs from the previous frame */
    double walk;            /* this view's camera on the walk, 0..1 */
    int occluders;          /* 1: the engine draws its occluders */
    int cancelled;          /* 1: a cancelled frame came just before this frame */
    int viewport[4];        /* x, y, w, h in the framebuffer */
    int fb_w, fb_h;         /* the framebuffer */
} sq_view;

/* what the view function measured */
typedef struct sq_check {
    long pixels;          /* pixels compared */
    long wrong;           /* of those, outside the bound */
    double max_err, bound; /* the largest error and the bound, in the test's unit */
} sq_check;

typedef struct sq_totals {
    int frames, views, cancels, changes; /* changes: frames that changed something */
    long pixels, wrong;
    double worst;         /* the largest max_err / bound of a view */
    int bad_frame, bad_view; /* the first view with a wrong pixel (-1: none) */
} sq_totals;

typedef void (*sq_view_fn)(void *user, const sq_view *v, sq_check *out);
typedef void (*sq_cancel_fn)(void *user, const sq_view *v);

/* Every change at least once, the camera in and out, in 6 frames: an occluder that goes away and
   comes back (a cached O), the viewport shrinking and growing (cached targets), a split frame
   after a cancelled one, and the first frame's input again at the end. */
#define SQ_DEFAULT_FRAMES 6
static const sq_step sq_default_script[SQ_DEFAULT_FRAMES] = {
    {{0.0, 0.0}, 1, 1, 0, 0},  {{0.5, 0.0}, 0, 1, 0, 0}, {{1.0, 0.0}, 1, 1, 1, 0},
    {{0.25, 0.75}, 1, 2, 0, 1}, {{0.0, 0.0}, 0, 1, 0, 1}, {{0.0, 0.0}, 1, 1, 0, 0},
};

/* A walk of n frames: the camera goes in (walk 0 -> 1) and out again, the occluders leave for 3
   frames in every 8, every 10th frame is a split screen (the second view further along), every
   11th follows a cancelled frame, every 13th, the first included, has the smaller viewport (so
   the frames after the first need more than it did: anything sized once must grow). */
static inline int sq_walk_script(sq_step *out, int n)
{
    int i;
    for (i = 0; i < n; ++i) {
        double u = n > 1 ? (double)i / (n - 1) : 0.0;
        double w = u < 0.5 ? 2.0 * u : 2.0 * (1.0 - u);
        memset(&out[i], 0, sizeof out[i]);
        out[i].walk[0] = w;
        out[i].walk[1] = w < 0.6 ? w + 0.4 : w - 0.4;
        out[i].occluders = (i % 8) < 5;
        out[i].views = (i % 10) == 9 ? 2 : 1;
        out[i].cancel = (i % 11) == 6;
        out[i].small = (i % 13) == 0;
    }
    return n;
}

/* The viewport of view k of a frame: full, the smaller rectangle, or a half of a split screen. */
static inline void sq_viewport(int w, int h, int small, int views, int k, int vp[4])
{
    if (views == 2) {
        vp[0] = k ? w / 2 : 0;
        vp[1] = 0;
        vp[2] = k ? w - w / 2 : w / 2;
        vp[3] = h;
    } else if (small) { /* odd sizes, at an offset */
        vp[0] = w / 8;
        vp[1] = h / 6;
        vp[2] = w - w / 4 - 3;
        vp[3] = h - h / 3 - 1;
    } else {
        vp[0] = vp[1] = 0;
        vp[2] = w;
        vp[3] = h;
    }
}

/* "frame 3 view 1/2 (walk 0.75, occluders, split, after a cancelled frame)" */
static inline const char *sq_describe(const sq_view *v, char *buf, size_t size)
{
    snprintf(buf, size, "frame %d view %d/%d (walk %.2f, %s, viewport %d,%d %dx%d%s)", v->frame, v->view + 1,
             v->views, v->walk, v->occluders ? "occluders" : "no occluders", v->viewport[0], v->viewport[1],
             v->viewport[2], v->viewport[3], v->cancelled ? ", after a cancelled frame" : "");
    return buf;
}

/* Plays the script (steps[0..n-1]) with what allow does not name held still (the first frame's
   camera, occluders on, the full viewport, one view, nothing cancelled) and prints one line per
   sequence; where says where the first wrong pixel was (size >= 200). n >= 4. */
static inline sq_totals sq_play(const char *name, int w, int h, const sq_step *steps, int n, unsigned allow,
                                sq_view_fn view_fn, sq_cancel_fn cancel_fn, void *user, char *where)
{
    sq_totals t;
    sq_view prev;
    int f, k;
    memset(&t, 0, sizeof t);
    memset(&prev, 0, sizeof prev);
    t.bad_frame = t.bad_view = -1;
    where[0] = 0;
    assert_true(n >= 4);
    for (f = 0; f < n; ++f) {
        sq_step s = steps[f];
        sq_view v;
        if (!(allow & SQ_CAMERA)) s.walk[0] = s.walk[1] = steps[0].walk[0];
        if (!(allow & SQ_OCCLUDER)) s.occluders = 1;
        if (!(allow & SQ_RESIZE)) s.small = 0;
        if (!(allow & SQ_SPLIT)) s.views = 1;
        if (!(allow & SQ_CANCEL) || !cancel_fn) s.cancel = 0;
        if (s.views != 2) s.views = 1;
        memset(&v, 0, sizeof v);
        v.frame = f;
        v.views = s.views;
        v.occluders = s.occluders;
        v.cancelled = s.cancel;
        v.fb_w = w;
        v.fb_h = h;
        if (f > 0) {
            int vp[4];
            sq_viewport(w, h, s.small, s.views, 0, vp);
            v.changes |= s.walk[0] != prev.walk ? SQ_CAMERA : 0u;
            v.changes |= s.occluders != prev.occluders ? SQ_OCCLUDER : 0u;
            v.changes |= memcmp(vp, prev.viewport, sizeof vp) && s.views == 1 && prev.views == 1 ? SQ_RESIZE : 0u;
            v.changes |= s.views != prev.views ? SQ_SPLIT : 0u;
            v.changes |= s.cancel ? SQ_CANCEL : 0u;
            t.changes += v.changes != 0;
        }
        if (s.cancel) {
            v.walk = s.walk[0];
            sq_viewport(w, h, s.small, s.views, 0, v.viewport);
            cancel_fn(user, &v);
            t.cancels++;
        }
        for (k = 0; k < s.views; ++k) {
            sq_check c;
            v.view = k;
            v.walk = s.walk[k];
            sq_viewport(w, h, s.small, s.views, k, v.viewport);
            memset(&c, 0, sizeof c);
            view_fn(user, &v, &c);
            t.views++;
            t.pixels += c.pixels;
            t.wrong += c.wrong;
            if (c.bound > 0 && c.max_err / c.bound > t.worst) t.worst = c.max_err / c.bound;
            if (c.wrong && t.bad_frame < 0) {
                t.bad_frame = f;
                t.bad_view = k;
                sq_describe(&v, where, 200);
            }
        }
        v.view = 0;
        v.walk = s.walk[0];
        sq_viewport(w, h, s.small, s.views, 0, v.viewport);
        prev = v;
        t.frames++;
    }
    print_message("# sequence %-44s %2d frames, %2d views, %d cancelled, %d changed: %ld wrong of %ld pixels "
                  "(worst error %.2f of the bound)\n",
                  name, t.frames, t.views, t.cancels, t.changes, t.wrong, t.pixels, t.worst);
    assert_true(t.changes >= 3 || !(allow & (SQ_CAMERA | SQ_OCCLUDER)));
    return t;
}

/* sq_play, and the running test fails if a view had a wrong pixel (after the whole sequence). */
static inline sq_totals sq_run(const char *name, int w, int h, const sq_step *steps, int n, unsigned allow,
                               sq_view_fn view_fn, sq_cancel_fn cancel_fn, void *user)
{
    char where[200];
    sq_totals t = sq_play(name, w, h, steps, n, allow, view_fn, cancel_fn, user, where);
    if (t.wrong) fail_msg("sequence %s: %ld wrong pixels; the first in %s", name, t.wrong, where);
    return t;
}

#endif
