// Host/device portability macro for the KAGE semantics library.
//
// Every semantic function is written once and compiled three ways: by nvcc
// (host and device), by NVRTC (device only, no std headers), and by a plain
// host compiler (the CPU reference path and the tests).
#pragma once

#if defined(__CUDACC_RTC__)
#define KAGE_HD __device__ __forceinline__
#elif defined(__CUDACC__)
#define KAGE_HD __host__ __device__ __forceinline__
#else
#define KAGE_HD inline
#endif

// Loop unrolling hint: honoured by nvcc and NVRTC, absent for host compilers (which warn on it).
#if defined(__CUDACC__) || defined(__CUDACC_RTC__)
#define KAGE_UNROLL _Pragma("unroll")
#else
#define KAGE_UNROLL
#endif

#if defined(__CUDACC_RTC__)
// NVRTC has no libc headers; the fixed-width types come from the builtins.
typedef unsigned char uint8_t;
typedef unsigned short uint16_t;
typedef unsigned int uint32_t;
typedef unsigned long long uint64_t;
typedef signed char int8_t;
typedef int int32_t;
typedef long long int64_t;
#else
#include <cstdint>
#endif
