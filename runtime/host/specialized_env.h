// The path generated sources include for their host entry points (templates/kernels.cu.in); the code
// is in runtime/cpu/specialized_env.h. Kept so that generated files, and the hashes they record, stay
// byte-identical across the move to runtime/cpu.
#pragma once

#include "runtime/cpu/specialized_env.h"
