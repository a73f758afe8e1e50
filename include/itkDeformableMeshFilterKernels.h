/*=========================================================================
 *
 *  Copyright NumFOCUS
 *
 *  Licensed under the Apache License, Version 2.0 (the "License");
 *  you may not use this file except in compliance with the License.
 *  You may obtain a copy of the License at
 *
 *         http://www.apache.org/licenses/LICENSE-2.0.txt
 *
 *  Unless required by applicable law or agreed to in writing, software
 *  distributed under the License is distributed on an "AS IS" BASIS,
 *  WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
 *  See the License for the specific language governing permissions and
 *  limitations under the License.
 *
 *=========================================================================*/
#ifndef itkDeformableMeshFilterKernels_h
#define itkDeformableMeshFilterKernels_h

#include "itkDeformableMeshFilterDetail.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

// The step's kernels, compiled for several instruction sets in one binary:
// the same code (itkDeformableMeshFilterVec4.inc, itkDeformableMeshFilterKernelBody.inc)
// is included once per instruction set, each time in a namespace of its own,
// and the AVX2 one under a target pragma, so that a portable build carries an
// AVX2 and FMA path that GetKernelPath() selects on processors that have
// them. The macros below are undefined at the end of this header.

#if defined(__x86_64__) || defined(_M_X64)
#  include <immintrin.h>
#  define EDM_KERNELS_SSE2 1
#else
#  define EDM_KERNELS_SSE2 0
#endif
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
#  define EDM_KERNELS_AVX2 1
#else
#  define EDM_KERNELS_AVX2 0
#endif

#if defined(__GNUC__) || defined(__clang__)
#  define EDM_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#  define EDM_ALWAYS_INLINE inline
#endif
#if defined(__GNUC__) && !defined(__clang__)
#  define EDM_UNROLL_2 _Pragma("GCC unroll 2")
#  define EDM_UNROLL_8 _Pragma("GCC unroll 8")
#else
#  define EDM_UNROLL_2
#  define EDM_UNROLL_8
#endif

#define EDM_ISA_PORTABLE 0
#define EDM_ISA_SSE2 1
#define EDM_ISA_AVX2 2

namespace itk
{
namespace DeformableMeshFilterDetail
{
namespace Portable
{
#define EDM_KERNEL_ISA EDM_ISA_PORTABLE
#include "itkDeformableMeshFilterVec4.inc"
#include "itkDeformableMeshFilterKernelBody.inc"
#undef EDM_KERNEL_ISA
} // namespace Portable

#if EDM_KERNELS_SSE2
namespace SSE2
{
#  define EDM_KERNEL_ISA EDM_ISA_SSE2
#  include "itkDeformableMeshFilterVec4.inc"
#  include "itkDeformableMeshFilterKernelBody.inc"
#  undef EDM_KERNEL_ISA
} // namespace SSE2
#endif

#if EDM_KERNELS_AVX2
#  if defined(__clang__)
#    pragma clang attribute push(__attribute__((target("avx2,fma"))), apply_to = function)
#  else
#    pragma GCC push_options
#    pragma GCC target("avx2,fma")
#  endif
namespace AVX2FMA
{
#  define EDM_KERNEL_ISA EDM_ISA_AVX2
#  include "itkDeformableMeshFilterVec4.inc"
#  include "itkDeformableMeshFilterKernelBody.inc"
#  undef EDM_KERNEL_ISA
} // namespace AVX2FMA
#  if defined(__clang__)
#    pragma clang attribute pop
#  else
#    pragma GCC pop_options
#  endif
#endif

/** The geometry pass of a work block on \a path; returns, when \a needLengths,
 * the sum of its vertices' mean squared edge lengths, else 0 (see
 * GeometryBlock()). */
inline double
RunGeometryBlock(KernelPath         path,
                 bool               needNormal,
                 bool               ordered,
                 bool               needLengths,
                 const MeshTables & mesh,
                 const StepArrays & arrays,
                 double             orientationSign,
                 SizeValueType      begin,
                 SizeValueType      end)
{
  double squaredEdgeSum = 0.0;
  WithConstant(needNormal, [&](auto normal) {
    WithConstant(ordered, [&](auto inOrder) {
      WithConstant(needLengths, [&](auto withLengths) {
        constexpr bool NeedNormal = decltype(normal)::value;
        constexpr bool Ordered = decltype(inOrder)::value;
        constexpr bool NeedLengths = decltype(withLengths)::value;
        switch (path)
        {
#if EDM_KERNELS_AVX2
          case KernelPath::AVX2FMA:
            squaredEdgeSum =
              AVX2FMA::GeometryBlock<NeedNormal, Ordered, NeedLengths>(mesh, arrays, orientationSign, begin, end);
            return;
#endif
#if EDM_KERNELS_SSE2
          case KernelPath::SSE2:
            squaredEdgeSum =
              SSE2::GeometryBlock<NeedNormal, Ordered, NeedLengths>(mesh, arrays, orientationSign, begin, end);
            return;
#endif
          default:
            squaredEdgeSum =
              Portable::GeometryBlock<NeedNormal, Ordered, NeedLengths>(mesh, arrays, orientationSign, begin, end);
        }
      });
    });
  });
  return squaredEdgeSum;
}

/** The step of a work block on \a path; returns its largest displacement. */
template <typename TPixel>
double
RunStepBlock(KernelPath                   path,
             bool                         useRigidity,
             bool                         useNormal,
             bool                         ordered,
             const ForceSampler<TPixel> & sampler,
             const MeshTables &           mesh,
             const StepTerms &            terms,
             const StepArrays &           arrays,
             SizeValueType                begin,
             SizeValueType                end,
             bool                         diagnose)
{
  double largest = 0.0;
  WithConstant(useRigidity, [&](auto rigidity) {
    WithConstant(useNormal, [&](auto normal) {
      WithConstant(ordered, [&](auto inOrder) {
        constexpr bool UseRigidity = decltype(rigidity)::value;
        constexpr bool UseNormal = decltype(normal)::value;
        constexpr bool Ordered = decltype(inOrder)::value;
        switch (path)
        {
#if EDM_KERNELS_AVX2
          case KernelPath::AVX2FMA:
            largest = AVX2FMA::StepBlock<TPixel, UseRigidity, UseNormal, Ordered>(
              sampler, mesh, terms, arrays, begin, end, diagnose);
            return;
#endif
#if EDM_KERNELS_SSE2
          case KernelPath::SSE2:
            largest = SSE2::StepBlock<TPixel, UseRigidity, UseNormal, Ordered>(
              sampler, mesh, terms, arrays, begin, end, diagnose);
            return;
#endif
          default:
            largest = Portable::StepBlock<TPixel, UseRigidity, UseNormal, Ordered>(
              sampler, mesh, terms, arrays, begin, end, diagnose);
        }
      });
    });
  });
  return largest;
}
} // namespace DeformableMeshFilterDetail
} // namespace itk

#undef EDM_KERNELS_SSE2
#undef EDM_KERNELS_AVX2
#undef EDM_ALWAYS_INLINE
#undef EDM_UNROLL_2
#undef EDM_UNROLL_8
#undef EDM_ISA_PORTABLE
#undef EDM_ISA_SSE2
#undef EDM_ISA_AVX2

#endif
