#pragma once
// Internal: the elementary functions (exp, log, pow, log1p, erfc) that learning and search use, with the same
// bits on every x86-64 (and every other) CPU.
//
// Why not std::exp and friends: glibc picks among several builds of exp, log and pow at run time
// by the CPU's features (with FMA and AVX2 or without; GLIBC_TUNABLES=glibc.cpu.hwcaps can
// change the pick), and they may differ in the last bit. A policy trained with the same seed
// would then differ between machines once one such bit flips a sampled choice. SLEEF's
// "deterministic" scalar functions (the `cinz` family, pure C, no FMA) give the same result on
// every machine and build; their error is at most 1 ulp (the `u10` variants). Only the library's
// own numerics go through here: OMPL, FCL and KDL call libm themselves.
//
// Cost: a few tens of nanoseconds a call, against a few for glibc's; these are called per sample
// in training and once per tree node in search, never in an inner loop of the solvers.

#include <sleef.h>

namespace ontime {

inline double portable_exp(double x) noexcept { return Sleef_cinz_expd1_u10purec(x); }
inline double portable_log(double x) noexcept { return Sleef_cinz_logd1_u10purec(x); }
inline double portable_pow(double x, double y) noexcept { return Sleef_cinz_powd1_u10purec(x, y); }
inline double portable_log1p(double x) noexcept { return Sleef_cinz_log1pd1_u10purec(x); }
// (At most 1.5 ulp.)
inline double portable_erfc(double x) noexcept { return Sleef_cinz_erfcd1_u15purec(x); }
// 1 / (1 + e^-x), with no overflow of e^-x for large negative x.
inline double portable_logistic(double x) noexcept {
  return x >= 0 ? 1 / (1 + portable_exp(-x)) : portable_exp(x) / (1 + portable_exp(x));
}

}  // namespace ontime
