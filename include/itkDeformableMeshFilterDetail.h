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
#ifndef itkDeformableMeshFilterDetail_h
#define itkDeformableMeshFilterDetail_h

#include "itkIntTypes.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <type_traits>
#include <vector>

namespace itk
{
// What DeformableMeshFilter shares with its step kernels
// (itkDeformableMeshFilterKernels.h): plain data whose layout does not depend
// on compile flags, so that code built with different flags (a program, the
// VTK library) agrees on the filter's members; and the choice of the kernel
// path at run time.
namespace DeformableMeshFilterDetail
{
/** Vertices in a chunk: the forces of a chunk are sampled together, the
 * normals of a chunk are scaled together, and on meshes of mixed valences the
 * vertices of a chunk are processed in the order of their valences. */
constexpr SizeValueType ChunkSize = 32;

/** Vertices in a work block, the unit of work the threads share. Fixed, so
 * that the result does not depend on the number of threads. */
constexpr SizeValueType BlockSize = 512;
static_assert(BlockSize % ChunkSize == 0, "blocks are made of whole chunks");

/** How the neighbours of a vertex are stored: as the ordered ring of a
 * closed fan of triangles (interior vertex), as an open fan (boundary
 * vertex), or unordered with the vertex's triangles kept apart (any other
 * case: polygons, lines, non-manifold vertices, and every vertex of a 2-D
 * contour, whose segments are kept apart as its "triangles"). */
enum RingKind : uint8_t
{
  ClosedRing = 0,
  OpenRing = 1,
  GeneralVertex = 2
};

/** What the step reads of the force image. Continuous index
 * c = columns * x - offset (columns of the physical-to-index matrix); inside
 * when lower <= c < upper on every axis. */
template <typename TPixel>
struct ForceSampler
{
  double         columns[3][3]{}; // columns[c][r]: row r of column c
  double         offset[3]{};
  double         lower[3]{};
  double         upper[3]{};
  double         byteStrides[3]{}; // bytes from a pixel to the next along x, y, z
  const TPixel * buffer{ nullptr };
  bool           smallBuffer{ false }; // byte offsets fit in 32 bits
  int64_t        last[3]{};            // last index along x, y, z
  int64_t        strideY{ 0 };
  int64_t        strideZ{ 0 };
  int64_t        lastPixel{ 0 };
};

/** The mesh's tables, unpacked once per reset (see BuildTopology()). */
struct MeshTables
{
  const uint32_t * neighbourOffsets;   // CSR: neighbours of i in [offsets[i], offsets[i + 1])
  const uint32_t * neighbours;         // ring-ordered for ClosedRing and OpenRing vertices
  const uint8_t *  ringKinds;          // RingKind of each vertex
  const uint32_t * generalVertices;    // the GeneralVertex vertices, sorted
  SizeValueType    numberOfGeneral;    // how many
  const uint32_t * generalPairOffsets; // CSR by rank in generalVertices
  const uint32_t * generalPairs;       // (b, c): edges opposite the vertex in its triangles
  const uint8_t *  valenceOrder;       // per chunk, offsets in valence order; null when unused
  // 2-D contours (points (x, y, 0)): the pairs (b, c) of a GeneralVertex are
  // then the directed segments b -> c of its contours, and its normal the sum
  // of (c - b) x z (the right of the direction of travel: outward for a
  // counter-clockwise closed contour).
  bool contour{ false };
};

/** The weights of the terms of one step, as the step uses them (Elasticity
 * and Rigidity already scaled so that a + 2b <= 1). */
struct StepTerms
{
  double scaleFactor;
  double elasticity;
  double rigidity;
  bool   tangential;
  double balloon;
  double maximumStep;
  double orientationSign; // +1 outward-oriented mesh, -1 inward
  // SuppressTangentialDrift: below this external displacement (mm) the
  // external force acts along the normal only, above twice it whole (h/8
  // and h/4, h the root mean square edge length); 0: off.
  double driftThreshold;
};

/** The per-vertex arrays a step reads and writes. */
struct StepArrays
{
  const double * coordinates;     // 3 per vertex, then one readable value
  double *       next;            // 3 per vertex, then one writable value
  float *        umbrella;        // 4 per vertex (geometry pass)
  float *        normals;         // 4 per vertex, outward unit (geometry pass)
  uint8_t *      balloonReleased; // 1 per vertex
  const float *  normalSpeeds;    // 1 per vertex, outward (image terms); null when off
  float *        displacementMagnitudes;
  float *        externalMagnitudes;
  float *        internalMagnitudes;
};

/** The instruction sets the step is compiled for. */
enum class KernelPath : int
{
  Portable = 0, // plain C++, any processor
  SSE2 = 1,     // x86-64 baseline
  AVX2FMA = 2   // x86-64 with AVX2 and FMA, chosen at run time
};

inline const char *
KernelPathName(KernelPath path)
{
  switch (path)
  {
    case KernelPath::AVX2FMA:
      return "avx2";
    case KernelPath::SSE2:
      return "sse2";
    default:
      return "portable";
  }
}

/** True when this build has the path and the processor can run it. */
inline bool
KernelPathAvailable(KernelPath path)
{
  switch (path)
  {
    case KernelPath::Portable:
      return true;
    case KernelPath::SSE2:
#if defined(__x86_64__) || defined(_M_X64)
      return true;
#else
      return false;
#endif
    case KernelPath::AVX2FMA:
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__)
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
      return false;
#endif
  }
  return false;
}

/** The path the environment variable EDM_KERNEL_PATH names (avx2, sse2,
 * portable) when it is available, else the fastest available one. */
inline KernelPath
DefaultKernelPath()
{
  const KernelPath paths[] = { KernelPath::AVX2FMA, KernelPath::SSE2, KernelPath::Portable };
  if (const char * requested = std::getenv("EDM_KERNEL_PATH"))
  {
    for (const KernelPath path : paths)
    {
      if (std::strcmp(requested, KernelPathName(path)) == 0 && KernelPathAvailable(path))
      {
        return path;
      }
    }
  }
  for (const KernelPath path : paths)
  {
    if (KernelPathAvailable(path))
    {
      return path;
    }
  }
  return KernelPath::Portable;
}

/** The process-wide choice, initialised from DefaultKernelPath(). */
inline std::atomic<int> &
KernelPathChoice()
{
  static std::atomic<int> choice{ static_cast<int>(DefaultKernelPath()) };
  return choice;
}

/** The path the step uses. */
inline KernelPath
GetKernelPath()
{
  return static_cast<KernelPath>(KernelPathChoice().load(std::memory_order_relaxed));
}

/** Forces a path for the whole process (tests, benchmarks); returns false,
 * and changes nothing, when it is not available. */
inline bool
SetKernelPath(KernelPath path)
{
  if (!KernelPathAvailable(path))
  {
    return false;
  }
  KernelPathChoice().store(static_cast<int>(path), std::memory_order_relaxed);
  return true;
}

/** Calls f(std::true_type()) or f(std::false_type()) as \a value: a run-time
 * flag turned into a template argument. */
template <typename TFunction>
inline void
WithConstant(bool value, TFunction && f)
{
  if (value)
  {
    f(std::true_type());
  }
  else
  {
    f(std::false_type());
  }
}

/** Sorts edge keys (smaller point << 32 | larger point) into the order of
 * std::sort: a counting sort on the smaller point, then each point's few
 * keys in order. On the 6 million keys of a million-point surface std::sort
 * fell back to its heapsort: a reset and one iteration took 470 ms instead
 * of 235. Keys whose smaller point is not below \a numberOfPoints:
 * std::sort. */
inline void
SortEdgeKeys(std::vector<uint64_t> & keys, SizeValueType numberOfPoints)
{
  std::vector<SizeValueType> start(numberOfPoints + 1, 0);
  for (const uint64_t key : keys)
  {
    const uint64_t smaller = key >> 32;
    if (smaller >= numberOfPoints)
    {
      std::sort(keys.begin(), keys.end());
      return;
    }
    ++start[smaller + 1];
  }
  for (SizeValueType i = 0; i < numberOfPoints; ++i)
  {
    start[i + 1] += start[i];
  }
  std::vector<uint64_t> sorted(keys.size());
  {
    std::vector<SizeValueType> cursor(start.begin(), start.end() - 1);
    for (const uint64_t key : keys)
    {
      sorted[cursor[key >> 32]++] = key;
    }
  }
  for (SizeValueType i = 0; i < numberOfPoints; ++i)
  {
    const auto first = sorted.begin() + static_cast<std::ptrdiff_t>(start[i]);
    const auto last = sorted.begin() + static_cast<std::ptrdiff_t>(start[i + 1]);
    if (last - first <= 16)
    {
      // Insertion sort: a point has about three keys as the smaller point.
      for (auto k = first + (first != last ? 1 : 0); k < last; ++k)
      {
        const uint64_t key = *k;
        auto           j = k;
        for (; j > first && *(j - 1) > key; --j)
        {
          *j = *(j - 1);
        }
        *j = key;
      }
    }
    else
    {
      std::sort(first, last);
    }
  }
  keys.swap(sorted);
}

} // namespace DeformableMeshFilterDetail
} // namespace itk

#endif
