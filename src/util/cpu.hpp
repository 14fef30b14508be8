#pragma once
// What the CPU runs, asked once by the code that picks an instruction set at run time (bvh-wide's
// traversals, bvh-design's box counts): the library itself is built for the baseline x86-64.

namespace rtcost {

/// Whether this CPU (and its operating system) runs AVX2; false off x86-64.
bool cpu_has_avx2();

}  // namespace rtcost
