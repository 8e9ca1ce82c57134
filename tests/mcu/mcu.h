/*
 * mcu.h - what startup.c offers the firmware tests: raw semihosting output,
 * a failing exit that never returns, and stack high-water measurement.
 * On the host (no __arm__) the stack functions report 0.
 */
#ifndef CDSP_TESTS_MCU_H
#define CDSP_TESTS_MCU_H

#include <stddef.h>

#if defined(__arm__)
void mcu_puts_raw(const char *s);
void mcu_abort_exit(void);
/* Repaint the free stack below the caller; returns the mark for mcu_stack_peak. */
void *mcu_stack_mark(void);
/* Bytes of stack used below the mark since it was set. */
size_t mcu_stack_peak(const void *mark);
size_t mcu_stack_size(void);
#endif

#endif
