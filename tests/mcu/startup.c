/*
 * startup.c - reset handler, vector table and semihosting helpers for the
 * firmware tests under qemu-system-arm (mps2-an385/an386/an500).
 *
 * newlib's crt0 locks up on these boards (shared/FACTS.md), so the firmware
 * brings itself up: copy .data from flash, zero .bss, enable the FPU when
 * there is one, paint the stack, open the semihosting handles, then
 * exit(main()). Any fault prints its name over semihosting and stops QEMU
 * with a failing status, so a crashing firmware never hangs `make check`.
 *
 * The stack is painted with a pattern at reset; mcu_stack_mark() repaints
 * the unused part below the caller and mcu_stack_peak() reports how deep the
 * stack went since the mark: the measured counterpart of `make stack`.
 */
#include <stdint.h>
#include <stdlib.h>
#include "mcu.h"

extern uint32_t __mcu_data_load[], __mcu_data_start[], __mcu_data_end[];
extern uint32_t __mcu_bss_start[], __mcu_bss_end[];
extern uint32_t __mcu_stack_top[], __mcu_stack_limit[];

extern void initialise_monitor_handles(void);
int main(void);
void mcu_reset(void);
void mcu_fault(void);
void _init(void);
void _fini(void);

#define MCU_PAINT 0xC5D5C5D5u

/* Semihosting call (ARM DUI 0471: BKPT 0xAB, operation in r0, argument in r1). */
static uint32_t semihost(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

void mcu_puts_raw(const char *s)
{
    semihost(0x04u, s); /* SYS_WRITE0 */
}

void mcu_abort_exit(void)
{
    /* SYS_EXIT with ADP_Stopped_RunTimeErrorUnknown: QEMU exits with 1. */
    semihost(0x18u, (const void *)0x20023u);
    for (;;)
        ;
}

/* Everything below the current stack pointer is free (no interrupts run
 * in these tests): paint [limit, sp) so the next call starts clean. */
static inline uint32_t *current_sp(void)
{
    uint32_t *sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    return sp;
}

void *mcu_stack_mark(void)
{
    uint32_t *sp = current_sp(), *p;
    for (p = __mcu_stack_limit; p < sp; p++)
        *p = MCU_PAINT;
    return sp;
}

size_t mcu_stack_peak(const void *mark)
{
    const uint32_t *p = __mcu_stack_limit;
    while (p < (const uint32_t *)mark && *p == MCU_PAINT)
        p++;
    return (size_t)((const char *)mark - (const char *)p);
}

size_t mcu_stack_size(void)
{
    return (size_t)((char *)__mcu_stack_top - (char *)__mcu_stack_limit);
}

void mcu_reset(void)
{
    uint32_t *src = __mcu_data_load, *dst;
    for (dst = __mcu_data_start; dst < __mcu_data_end;)
        *dst++ = *src++;
    for (dst = __mcu_bss_start; dst < __mcu_bss_end;)
        *dst++ = 0;
#if defined(__ARM_FP)
    /* CPACR (0xE000ED88): full access to CP10 and CP11, bits 20-23. */
    *(volatile uint32_t *)0xE000ED88u |= 0xFu << 20;
    __asm__ volatile("dsb\n\tisb" ::: "memory");
#endif
    (void)mcu_stack_mark();
    initialise_monitor_handles();
    exit(main());
}

void mcu_fault(void)
{
    mcu_puts_raw("MCU FAULT: hard fault / NMI / unhandled exception\n");
    mcu_abort_exit();
}

/* newlib's exit() calls _fini via __libc_fini_array; crti/crtn are not
 * linked (-nostartfiles), so they are provided empty here. */
void _init(void) {}
void _fini(void) {}

/* Cortex-M vector table: initial SP, reset, then the system exceptions
 * (NMI, HardFault, MemManage, BusFault, UsageFault, ..., SysTick) and a few
 * interrupts, all routed to the fault handler. */
typedef void (*mcu_vector)(void);
__attribute__((section(".vectors"), used)) static const mcu_vector mcu_vectors[32] = {
    (mcu_vector)(uintptr_t)__mcu_stack_top, mcu_reset,
    mcu_fault, mcu_fault, mcu_fault, mcu_fault, mcu_fault, 0, 0, 0, 0,
    mcu_fault, mcu_fault, 0, mcu_fault, mcu_fault,
    mcu_fault, mcu_fault, mcu_fault, mcu_fault, mcu_fault, mcu_fault, mcu_fault, mcu_fault,
    mcu_fault, mcu_fault, mcu_fault, mcu_fault, mcu_fault, mcu_fault, mcu_fault, mcu_fault,
};
