"""The baseline's fast paths: the space-to-depth rearrangement and the Triton convolution kernels (--fused-input,
--triton-conv). Pure torch and triton: they import without the compiled extension."""
