/*
 * probe.c - a minimal firmware image around example.c for `make size`:
 * a vector table, a reset handler that starts main(), and do-nothing
 * application hooks. PROBE_POINTS links the points path, PROBE_FRAME the
 * frame path, both for the whole example; PROBE_ALL adds every public
 * function of cdsp.h (for the stack analysis' disassembly). Never run; only
 * measured (the map file attributes every byte to libcdsp, libm, libgcc,
 * libc or the application).
 */
#include <stdint.h>
#include "example.h"

extern uint32_t __mcu_data_load[], __mcu_data_start[], __mcu_data_end[];
extern uint32_t __mcu_bss_start[], __mcu_bss_end[];
extern uint32_t __mcu_stack_top[];
void mcu_reset(void);
int main(void);

size_t app_read_edges(cdsp_edge *buf, size_t cap)
{
    (void)buf;
    (void)cap;
    return 0;
}

const void *app_frame(int *width, int *height)
{
    static const uint8_t px[1];
    *width = *height = 1;
    return px;
}

void app_publish_pose(const cdsp_result *pose) { (void)pose; }
void app_no_pipe(const char *why) { (void)why; }
void app_fault(const char *what) { (void)what; }

#ifdef PROBE_ALL
/* Every function of the contract, kept by the linker. */
typedef void (*probe_fn)(void);
#define F(f) (probe_fn)(uintptr_t)(f)
static const probe_fn probe_all[] = {
    F(cdsp_strerror), F(cdsp_status_token), F(cdsp_rng_seed), F(cdsp_rng_u32),
    F(cdsp_rng_below), F(cdsp_rng_uniform), F(cdsp_rng_normal), F(cdsp_camera_check),
    F(cdsp_camera_distort), F(cdsp_camera_undistort), F(cdsp_camera_project),
    F(cdsp_camera_ray), F(cdsp_image_check), F(cdsp_edge_params_default),
    F(cdsp_edges_detect), F(cdsp_camera_undistort_edges), F(cdsp_svd3), F(cdsp_line_fit),
    F(cdsp_pair_params_default), F(cdsp_axis_solve), F(cdsp_params_default),
    F(cdsp_points_solve), F(cdsp_frame_solve), F(cdsp_result_point_distance),
    F(cdsp_scene_default), F(cdsp_render_scratch_size), F(cdsp_render),
    F(cdsp_cylinder_contours),
};
#undef F
#endif

int main(void)
{
    static const cdsp_camera cal = {500, 500, 319.5, 239.5, 0, 0, 0, 0, 0, 640, 480};
    pipe_init(&cal);
#ifdef PROBE_ALL
    {
        const probe_fn *volatile keep = probe_all;
        (void)keep;
    }
#endif
    for (;;) {
#ifdef PROBE_POINTS
        pipe_points_step();
#endif
#ifdef PROBE_FRAME
        pipe_frame_step();
#endif
    }
}

void mcu_reset(void)
{
    uint32_t *src = __mcu_data_load, *dst;
    for (dst = __mcu_data_start; dst < __mcu_data_end;)
        *dst++ = *src++;
    for (dst = __mcu_bss_start; dst < __mcu_bss_end;)
        *dst++ = 0;
#if defined(__ARM_FP)
    *(volatile uint32_t *)0xE000ED88u |= 0xFu << 20;
    __asm__ volatile("dsb\n\tisb" ::: "memory");
#endif
    (void)main();
}

typedef void (*probe_vector)(void);
__attribute__((section(".vectors"), used)) static const probe_vector probe_vectors[2] = {
    (probe_vector)(uintptr_t)__mcu_stack_top, mcu_reset};
