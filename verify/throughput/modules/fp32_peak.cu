// The device's FP32 rate, measured: every thread runs eight independent chains of fused multiply-adds
// (2 FLOPs each), enough to keep each SM's FP32 lanes busy; the result is stored so nothing is removed.
extern "C" __global__ void kage_fp32_peak(float* out, int iterations, float seed) {
  const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  float a[8];
#pragma unroll
  for (int k = 0; k < 8; ++k) a[k] = seed + static_cast<float>(i + k);
  for (int n = 0; n < iterations; ++n) {
#pragma unroll
    for (int k = 0; k < 8; ++k) a[k] = fmaf(a[k], 0.999999f, 1e-6f);
  }
  float sum = 0.0f;
#pragma unroll
  for (int k = 0; k < 8; ++k) sum += a[k];
  out[i] = sum;
}
