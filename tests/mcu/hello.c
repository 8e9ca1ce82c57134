/*
 * hello.c - the harness on its own: boots, prints over semihosting, checks
 * that .data was copied and .bss zeroed, does a little floating point (the
 * FPU is enabled on M4F/M7, soft float on M3), and returns 0 so QEMU exits 0.
 */
#include <stdio.h>
#include "mcu.h"

static volatile int mcu_hello_data = 42;
static volatile int mcu_hello_bss;

int main(void)
{
    volatile float x = 2.0f;
    volatile double y = 3.0;
    float xs = x * x * 0.25f;
    double ys = y / 3.0;
    printf("hello from %s: data=%d bss=%d x=%g y=%g stack=%u\n", MCU_BOARD, mcu_hello_data,
           mcu_hello_bss, (double)xs, ys, (unsigned)mcu_stack_size());
    if (mcu_hello_data != 42 || mcu_hello_bss != 0 || xs != 1.0f || ys != 1.0) {
        printf("hello: FAILED\n");
        return 1;
    }
    printf("hello: ok\n");
    return 0;
}
