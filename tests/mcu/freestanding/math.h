/*
 * math.h - stand-in for the riscv64-unknown-elf freestanding compile of
 * libcdsp (`make mcu`), where no C library is installed: gcc's own
 * include directory has no <math.h>. Every name the library uses maps to
 * the compiler's builtin: sqrt, fabs and isfinite become instructions
 * (rv64 D extension, -fno-math-errno); floor, ceil and the transcendental
 * functions stay calls to the standard names, which the firmware's libm
 * must provide (`make mcu` lists them from the object files).
 * -ffreestanding implies -fno-builtin, hence the explicit __builtin_ forms.
 */
#ifndef CDSP_FREESTANDING_MATH_H
#define CDSP_FREESTANDING_MATH_H

#define sqrt(x) __builtin_sqrt(x)
#define sqrtf(x) __builtin_sqrtf(x)
#define fabs(x) __builtin_fabs(x)
#define fabsf(x) __builtin_fabsf(x)
#define floor(x) __builtin_floor(x)
#define floorf(x) __builtin_floorf(x)
#define ceil(x) __builtin_ceil(x)
#define ceilf(x) __builtin_ceilf(x)
#define atan2(y, x) __builtin_atan2(y, x)
#define atan2f(y, x) __builtin_atan2f(y, x)
#define sin(x) __builtin_sin(x)
#define sinf(x) __builtin_sinf(x)
#define cos(x) __builtin_cos(x)
#define cosf(x) __builtin_cosf(x)
#define log(x) __builtin_log(x)
#define logf(x) __builtin_logf(x)
#define exp(x) __builtin_exp(x)
#define expf(x) __builtin_expf(x)
#define round(x) __builtin_round(x)
#define roundf(x) __builtin_roundf(x)
#define isfinite(x) __builtin_isfinite(x)

#endif
