/* scene_gt.h - the ground truth of every named scene of tests/scenes.h (g_scene_names), computed once
 * per program by gt_setup and freed by gt_teardown: the shared fixture of the tier tests (test_tiers,
 * test_gles). Include after tests/scenes.h; W and H are the picture's size. */
#ifndef FOGVOL_TESTS_SCENE_GT_H
#define FOGVOL_TESTS_SCENE_GT_H

#include <stdlib.h>
#include <string.h>

typedef struct gt_cache {
    double *gt, *slope;
    int *pairs;
    unsigned char *interior, *covered;
    int max_faces;
    double tmax;
} gt_cache;

static gt_cache g_gt[NSCENE];

/* the scenes, then each one's ray-cast thickness, face pairs, interior and covered pixels (once: a
   process that has them, or whose parent had them before fork, keeps them) */
static inline void gt_setup(void)
{
    int i;
    if (g_gt[0].gt) return;
    build_scenes();
    for (i = 0; i < NSCENE; ++i) {
        gt_cache *t = &g_gt[i];
        t->gt = (double *)calloc((size_t)W * H, sizeof(double));
        t->slope = (double *)calloc((size_t)W * H, sizeof(double));
        t->pairs = (int *)calloc((size_t)W * H, sizeof(int));
        t->interior = (unsigned char *)calloc((size_t)W * H, 1);
        t->covered = (unsigned char *)calloc((size_t)W * H, 1);
        ground_truth(&g_scenes[scene_index(g_scene_names[i])], t->gt, t->pairs, t->interior, t->covered,
                     &t->max_faces, &t->tmax, t->slope);
    }
}

/* the cmocka group set-up of the tier tests: gt_setup (their group teardowns print their tables, then
   call gt_teardown) */
static inline int gt_group_setup(void **state)
{
    (void)state;
    gt_setup();
    return 0;
}

static inline void gt_teardown(void)
{
    int i;
    for (i = 0; i < NSCENE; ++i) {
        free(g_gt[i].gt);
        free(g_gt[i].slope);
        free(g_gt[i].pairs);
        free(g_gt[i].interior);
        free(g_gt[i].covered);
        memset(&g_gt[i], 0, sizeof g_gt[i]);
    }
    free_scenes();
}

#endif
