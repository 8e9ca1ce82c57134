/*
 * probe.c - a minimal firmware image around example.c for `make size`:
 * a vector table, a reset handler that starts main(), and do-nothing
 * application hooks. PROBE_POINTS links the points path, PROBE_FRAME the
 * frame path, both for the whole example. Never run; only measured (the
 * map file attributes every byte to libcdsp, libm, libgcc, libc or this).
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

int main(void)
{
    static const cdsp_camera cal = {500, 500, 319.5, 239.5, 0, 0, 0, 0, 0, 640, 480};
    pipe_init(&cal);
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
