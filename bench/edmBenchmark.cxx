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

// Throughput of the explicit deformable model against its anchors, on the
// seed's ellipsoid phantom (scaled to 128^3 voxels) and geodesic spheres of
// about 10k, 100k and 1M vertices:
//   EDM/DeformableMesh          our DeformableMeshFilter, external forces +
//                               Elasticity + Rigidity, 1 and 2 threads;
//   EDM/KernelPath              the same step on each kernel path (AVX2+FMA,
//                               SSE2, portable), 100k vertices, 1 thread;
//   ITK/DeformableSimplexMesh3D ITK's simplex-mesh model (serial), on the
//                               simplex mesh dual to a triangle mesh with about
//                               as many triangles as the others have vertices;
//   VTK/ProbeWarp               the seed's VTK loop, vtkProbeFilter then
//                               vtkWarpVector (external force only), when VTK
//                               is found;
//   EDM/ExternalForce           the force-field filter on 128^3 and 256^3;
//   ITK/GradientTwice           two ITK GradientImageFilter passes, the least
//                               work that grad |grad I| needs;
//   EDM/StateMemory             bytes per vertex of the filter's iteration
//                               state (must stay under 200).
// A summary of the ratios follows the benchmark table; the exit code is
// non-zero when the memory check fails.

#include "edmBenchmarkCase.h"

#include "itkDefaultDynamicMeshTraits.h"
#include "itkDeformableSimplexMesh3DFilter.h"
#include "itkGradientImageFilter.h"
#include "itkMesh.h"
#include "itkMultiThreaderBase.h"
#include "itkThreadPool.h"
#include "itkSimplexMesh.h"
#include "itkTriangleCell.h"
#include "itkTriangleMeshToSimplexMeshFilter.h"

#ifdef EDM_BENCHMARK_WITH_VTK
#  include "vtkCellArray.h"
#  include "vtkFloatArray.h"
#  include "vtkImageData.h"
#  include "vtkNew.h"
#  include "vtkPointData.h"
#  include "vtkPoints.h"
#  include "vtkPolyData.h"
#  include "vtkProbeFilter.h"
#  include "vtkSMPTools.h"
#  include "vtkSmartPointer.h"
#  include "vtkWarpVector.h"
#endif

#include <benchmark/benchmark.h>

#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <memory>
#include <new>
#include <string>
#include <vector>

// Live and peak heap bytes, counted by the global allocation functions below:
// the memory check reads the iteration state exactly instead of guessing it
// from the resident set size.
namespace
{
std::atomic<int64_t> liveHeapBytes{ 0 };
std::atomic<int64_t> peakHeapBytes{ 0 };

void *
CountedAllocate(std::size_t size)
{
  void * p = std::malloc(size == 0 ? 1 : size);
  if (p == nullptr)
  {
    throw std::bad_alloc();
  }
  const int64_t live = liveHeapBytes.fetch_add(static_cast<int64_t>(malloc_usable_size(p)), std::memory_order_relaxed) +
                       static_cast<int64_t>(malloc_usable_size(p));
  int64_t peak = peakHeapBytes.load(std::memory_order_relaxed);
  while (live > peak && !peakHeapBytes.compare_exchange_weak(peak, live, std::memory_order_relaxed))
  {}
  return p;
}

void
CountedFree(void * p) noexcept
{
  if (p != nullptr)
  {
    liveHeapBytes.fetch_sub(static_cast<int64_t>(malloc_usable_size(p)), std::memory_order_relaxed);
    std::free(p);
  }
}
} // namespace

void *
operator new(std::size_t size)
{
  return CountedAllocate(size);
}
void *
operator new[](std::size_t size)
{
  return CountedAllocate(size);
}
void
operator delete(void * p) noexcept
{
  CountedFree(p);
}
void
operator delete[](void * p) noexcept
{
  CountedFree(p);
}
void
operator delete(void * p, std::size_t) noexcept
{
  CountedFree(p);
}
void
operator delete[](void * p, std::size_t) noexcept
{
  CountedFree(p);
}

namespace
{
// The phantom, its force field and the geodesic spheres: edmBenchmarkCase.h.
using namespace edm::bench;

using SimplexTraits = itk::DefaultDynamicMeshTraits<double, 3, 3, double, double>;
using TriangleMeshType = itk::Mesh<double, Dimension, SimplexTraits>;
using SimplexMeshType = itk::SimplexMesh<double, Dimension, SimplexTraits>;
using SimplexModelType = itk::DeformableSimplexMesh3DFilter<SimplexMeshType, SimplexMeshType>;


/** Iterations per Update(): enough to make the per-update cost (copying the
 * cells, packing the points) small against the steps. */
unsigned int
StepsPerUpdate(int64_t vertices)
{
  return vertices >= 1000000 ? 5 : (vertices >= 100000 ? 20 : 100);
}

// Results for the summary, by benchmark name: the last run, and the best of
// the repetitions when there are several (the least disturbed by other work
// on a shared machine).
std::map<std::string, double> summaryRates;
std::map<std::string, double> summaryBestRates;
std::map<std::string, double> summaryCPUTimes; // CPU ns per vertex-iteration, the last run
std::map<std::string, double> summarySettled;  // the remeshing rows' rate over their last half, the last run

/** CPU time of the process (all threads), seconds: on a shared machine the
 * CPU time per vertex-iteration depends less on the other work than the
 * wall-clock rate does. */
double
ProcessCPUSeconds()
{
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

/** The counter of CPU nanoseconds (all threads) per vertex-iteration. */
void
SetCPUTimeCounter(benchmark::State & state, double cpuSeconds, double vertexIterations)
{
  if (vertexIterations > 0.0)
  {
    state.counters["cpu_ns/vertex_it"] = 1e9 * cpuSeconds / vertexIterations;
  }
}

/** Largest value over the repetitions: for a rate, the best repetition. */
double
Largest(const std::vector<double> & values)
{
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}
int64_t stateBytesPerVertex = -1;
int64_t peakBytesPerVertex = -1;

void
Record(const std::string & key, double rate)
{
  summaryRates[key] = rate;
}

std::string
SizeLabel(int64_t vertices)
{
  return vertices >= 1000000 ? "1M" : (vertices >= 100000 ? "100k" : "10k");
}

/** The global default number of threads while a benchmark runs. ITK's thread
 * pool is created at its first use with the global default of that moment, and
 * a PoolMultiThreader takes its maximum number of threads from the pool's
 * size: a pool created inside a 1-thread scope would leave every later
 * filter on one thread. The pool is grown here to the requested size first. */
class ThreadScope
{
public:
  explicit ThreadScope(unsigned int threads)
    : m_Saved(itk::MultiThreaderBase::GetGlobalDefaultNumberOfThreads())
  {
    auto * pool = itk::ThreadPool::GetInstance().GetPointer();
    if (pool->GetMaximumNumberOfThreads() < threads)
    {
      pool->AddThreads(threads - pool->GetMaximumNumberOfThreads());
    }
    itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(threads);
  }
  ~ThreadScope() { itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(m_Saved); }

private:
  unsigned int m_Saved;
};

// ---------------------------------------------------------------------------
// Our filter: external forces + Elasticity + Rigidity, tangential elasticity.
void
RunDeformableMesh(benchmark::State & state,
                  bool               internalForces,
                  unsigned int       threads,
                  bool               preventSelfIntersections = false)
{
  const int64_t      requested = state.range(0);
  ThreadScope        scope(threads);
  const MeshType *   input = ModelMesh(requested);
  const auto         vertices = static_cast<int64_t>(input->GetNumberOfPoints());
  const unsigned int steps = StepsPerUpdate(requested);

  auto model = ModelType::New();
  model->SetInput(input);
  model->SetForceImage(MeshForceImage());
  model->SetScaleFactor(0.5);
  model->SetElasticity(internalForces ? 0.3 : 0.0);
  model->SetRigidity(internalForces ? 0.1 : 0.0);
  model->SetIterateFromZero(false);
  model->SetNumberOfWorkUnits(threads == 1 ? 1 : 4 * threads);
  model->SetPreventSelfIntersections(preventSelfIntersections);
  model->SetNumberOfIterations(1);
  model->Update(); // Reset(): topology and state, outside the timing.

  int64_t      stepsRun = 0;
  const double cpuStart = ProcessCPUSeconds();
  for (auto _ : state)
  {
    model->SetNumberOfIterations(model->GetCurrentIteration() + steps);
    model->Update();
    stepsRun += steps;
  }
  SetCPUTimeCounter(state, ProcessCPUSeconds() - cpuStart, static_cast<double>(vertices * stepsRun));
  state.counters["vertices"] = static_cast<double>(vertices);
  state.counters["vertex_it/s"] =
    benchmark::Counter(static_cast<double>(vertices * stepsRun), benchmark::Counter::kIsRate);
  if (preventSelfIntersections)
  {
    state.counters["collisions"] = static_cast<double>(model->GetTotalNumberOfCollisionsPrevented());
  }
  state.SetLabel(
    std::string(itk::DeformableMeshFilterDetail::KernelPathName(itk::DeformableMeshFilterDetail::GetKernelPath())) +
    ", steps/update=" + std::to_string(steps) + (preventSelfIntersections ? ", collision test" : ""));
}

void
BM_EDM_DeformableMesh(benchmark::State & state)
{
  RunDeformableMesh(state, true, static_cast<unsigned int>(state.range(1)));
}

// The same run with PreventSelfIntersections on (issue 15 item 4): the
// collision test at every iteration.
void
BM_EDM_SelfIntersection(benchmark::State & state)
{
  RunDeformableMesh(state, true, static_cast<unsigned int>(state.range(1)), true);
}

// The same step on each kernel path (0 AVX2+FMA, 1 SSE2, 2 portable), forced
// for the run; 1 thread. Skipped where the processor lacks the path.
void
BM_EDM_KernelPath(benchmark::State & state)
{
  using itk::DeformableMeshFilterDetail::KernelPath;
  const KernelPath paths[] = { KernelPath::AVX2FMA, KernelPath::SSE2, KernelPath::Portable };
  const KernelPath path = paths[state.range(1)];
  const KernelPath saved = itk::DeformableMeshFilterDetail::GetKernelPath();
  if (!itk::DeformableMeshFilterDetail::SetKernelPath(path))
  {
    state.SkipWithError("kernel path not available on this processor");
    return;
  }
  RunDeformableMesh(state, true, 1);
  itk::DeformableMeshFilterDetail::SetKernelPath(saved);
}

// External force only: the same work as the VTK probe + warp loop.
void
BM_EDM_ExternalOnly(benchmark::State & state)
{
  RunDeformableMesh(state, false, static_cast<unsigned int>(state.range(1)));
}

// ---------------------------------------------------------------------------
// The animation case: one step per Update(), as a render loop raising
// NumberOfIterations by one; adds the per-update cost (output structure and
// points) to the step.
void
BM_EDM_OneStepPerUpdate(benchmark::State & state)
{
  const int64_t    requested = state.range(0);
  const MeshType * input = ModelMesh(requested);
  const auto       vertices = static_cast<int64_t>(input->GetNumberOfPoints());

  auto model = ModelType::New();
  model->SetInput(input);
  model->SetForceImage(MeshForceImage());
  model->SetScaleFactor(0.5);
  model->SetElasticity(0.3);
  model->SetRigidity(0.1);
  model->SetIterateFromZero(false);
  model->SetNumberOfIterations(1);
  model->Update();

  for (auto _ : state)
  {
    model->SetNumberOfIterations(model->GetCurrentIteration() + 1);
    model->Update();
  }
  state.counters["vertices"] = static_cast<double>(vertices);
  state.counters["vertex_it/s"] =
    benchmark::Counter(static_cast<double>(vertices * state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel("default threads");
}

// ---------------------------------------------------------------------------
// Issue 15: adaptive remeshing every 10 iterations (RemeshingEdgeLength the
// sphere's mean edge length, so that the remesher works on a mesh that the
// deformation keeps pulling out of the band), 2 threads, 20 steps per update
// (the output's triangle cells are rebuilt once per update after a
// remeshing); suppress_drift:1 is the filter's default (TangentialDrift
// SuppressWhenRemeshing: the surface at rest no longer flows along itself,
// and the remeshings after the first ones have little to do), 0 keeps the
// whole force (TangentialDrift Keep).
double
MeanEdgeLength(const MeshType * mesh)
{
  double      sum = 0.0;
  std::size_t count = 0;
  for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
  {
    const auto * ids = it.Value()->PointIdsBegin();
    for (unsigned int k = 0; k < 3; ++k)
    {
      sum += mesh->GetPoint(ids[k]).EuclideanDistanceTo(mesh->GetPoint(ids[(k + 1) % 3]));
      ++count;
    }
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

void
RunRemeshing(benchmark::State & state, bool collisions)
{
  const int64_t      requested = state.range(0);
  constexpr unsigned threads = 2;
  ThreadScope        scope(threads);
  const MeshType *   input = ModelMesh(requested);
  constexpr unsigned steps = 20;

  auto model = ModelType::New();
  model->SetInput(input);
  model->SetForceImage(MeshForceImage());
  model->SetScaleFactor(0.5);
  model->SetElasticity(0.3);
  model->SetRigidity(0.1);
  model->SetRemeshingEdgeLength(MeanEdgeLength(input));
  model->SetRemeshingInterval(10);
  model->SetPreventSelfIntersections(collisions);
  if (state.range(1) == 0)
  {
    model->SetSuppressTangentialDrift(false);
  }
  if (model->GetSuppressTangentialDrift() != (state.range(1) != 0))
  {
    state.SkipWithError("suppress_drift:1 must be the filter's default with remeshing");
    return;
  }
  model->SetIterateFromZero(false);
  model->SetNumberOfWorkUnits(4 * threads);
  model->SetNumberOfIterations(1);
  model->Update();

  int64_t                                  vertexIterations = 0;
  const ModelType::RemeshingStatisticsType before = model->GetRemeshingStatistics();
  const auto                               remeshingsBefore = model->GetNumberOfRemeshings();
  const double                             cpuStart = ProcessCPUSeconds();
  // Each update's vertex-iterations and seconds: the first updates carry
  // the sphere to the object (a third of the surface remeshed at each
  // remeshing at 1M), the later ones a surface that has settled.
  std::vector<std::pair<int64_t, double>> updates;
  for (auto _ : state)
  {
    const auto vertices = static_cast<int64_t>(model->GetOutput()->GetNumberOfPoints());
    const auto start = std::chrono::steady_clock::now();
    model->SetNumberOfIterations(model->GetCurrentIteration() + steps);
    model->Update();
    const int64_t done = steps * (vertices + static_cast<int64_t>(model->GetOutput()->GetNumberOfPoints())) / 2;
    updates.emplace_back(done, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    vertexIterations += done;
  }
  SetCPUTimeCounter(state, ProcessCPUSeconds() - cpuStart, static_cast<double>(vertexIterations));
  // The rate over the last half of the updates (the whole row's rate,
  // vertex_it/s, includes the travel).
  double settledVertexIterations = 0.0;
  double settledSeconds = 0.0;
  for (std::size_t k = updates.size() / 2; k < updates.size(); ++k)
  {
    settledVertexIterations += static_cast<double>(updates[k].first);
    settledSeconds += updates[k].second;
  }
  state.counters["settled_vertex_it/s"] = settledSeconds > 0.0 ? settledVertexIterations / settledSeconds : 0.0;
  state.counters["vertices"] = static_cast<double>(model->GetOutput()->GetNumberOfPoints());
  state.counters["remeshings"] = static_cast<double>(model->GetNumberOfRemeshings());
  // The operations of an average remeshing of the measured updates: how much
  // of the mesh each one rebuilds (the deformation keeps pulling edges out of
  // the band).
  const ModelType::RemeshingStatisticsType & after = model->GetRemeshingStatistics();
  const double remeshings = std::max(1.0, static_cast<double>(model->GetNumberOfRemeshings() - remeshingsBefore));
  state.counters["splits/remeshing"] = static_cast<double>(after.splits - before.splits) / remeshings;
  state.counters["collapses/remeshing"] = static_cast<double>(after.collapses - before.collapses) / remeshings;
  state.counters["flips/remeshing"] = static_cast<double>(after.flips - before.flips) / remeshings;
  if (collisions)
  {
    state.counters["collisions"] = static_cast<double>(model->GetTotalNumberOfCollisionsPrevented());
    state.counters["certified"] = static_cast<double>(model->GetNumberOfCertifiedSteps());
    state.counters["carried"] = static_cast<double>(model->GetNumberOfCarriedCertificates());
    state.counters["index_builds"] = static_cast<double>(model->GetNumberOfCollisionIndexRebuilds());
  }
  state.counters["vertex_it/s"] =
    benchmark::Counter(static_cast<double>(vertexIterations), benchmark::Counter::kIsRate);
  std::string label = collisions ? "remeshing every 10 iterations, collision test every iteration, steps/update=20"
                                 : "remeshing every 10 iterations, steps/update=20";
  state.SetLabel(label + (state.range(1) != 0 ? ", tangential drift suppressed (the default)" : ", whole force"));
}

void
BM_EDM_Remeshing(benchmark::State & state)
{
  RunRemeshing(state, false);
}

// Issue 15's combined speed target: remeshing every 10 iterations (as in
// BM_EDM_Remeshing) together with the collision test (PreventSelfIntersections)
// at every iteration, 2 threads, 20 steps per update. Each remeshing that
// changes the topology gives the collision test a new surface, whose index
// is rebuilt at the next step.
void
BM_EDM_CollisionsAndRemeshing(benchmark::State & state)
{
  RunRemeshing(state, true);
}

// Issue 15 item 5: the plain step on itk::RegularSphereMeshSource's sphere of
// 262 146 points (resolution 8), whose subdivisions number new points far
// from their neighbours; Elasticity 0.1, Rigidity 0.05, 2 threads; with the
// filter's renumbering for locality (range(0) = 1) and without.
void
BM_EDM_RegularSphereSource(benchmark::State & state)
{
  static MeshType::Pointer sphere = [] {
    MeshType::PointType centre;
    centre.Fill(MeshCentre);
    return itk::MakeSphereMesh<MeshType>(centre, InitialRadius, 8);
  }();
  constexpr unsigned threads = 2;
  ThreadScope        scope(threads);
  constexpr unsigned steps = 20;
  const auto         vertices = static_cast<int64_t>(sphere->GetNumberOfPoints());

  auto model = ModelType::New();
  model->SetInput(sphere);
  model->SetForceImage(MeshForceImage());
  model->SetScaleFactor(0.5);
  model->SetElasticity(0.1);
  model->SetRigidity(0.05);
  model->SetRenumberForLocality(state.range(0) != 0);
  model->SetIterateFromZero(false);
  model->SetNumberOfWorkUnits(4 * threads);
  model->SetNumberOfIterations(1);
  model->Update();

  int64_t      stepsRun = 0;
  const double cpuStart = ProcessCPUSeconds();
  for (auto _ : state)
  {
    model->SetNumberOfIterations(model->GetCurrentIteration() + steps);
    model->Update();
    stepsRun += steps;
  }
  SetCPUTimeCounter(state, ProcessCPUSeconds() - cpuStart, static_cast<double>(vertices * stepsRun));
  state.counters["vertices"] = static_cast<double>(vertices);
  state.counters["vertex_it/s"] =
    benchmark::Counter(static_cast<double>(vertices * stepsRun), benchmark::Counter::kIsRate);
  state.SetLabel(state.range(0) != 0 ? "renumbered for locality" : "input numbering");
}

// ---------------------------------------------------------------------------
// ITK's DeformableSimplexMesh3DFilter. The steps are timed without the
// per-update set-up (Initialize(): neighbour sets for every vertex), the
// same loop as its GenerateData().
class SimplexStepper : public SimplexModelType
{
public:
  ITK_DISALLOW_COPY_AND_MOVE(SimplexStepper);
  using Self = SimplexStepper;
  using Pointer = itk::SmartPointer<Self>;
  itkNewMacro(Self);

  void
  Start()
  {
    this->Initialize();
    this->m_Step = 0;
  }

  void
  Steps(unsigned int n)
  {
    for (unsigned int k = 0; k < n; ++k)
    {
      this->ComputeGeometry();
      if (this->m_Step % 10 == 0 && this->m_Step > 0)
      {
        this->UpdateReferenceMetrics();
      }
      this->ComputeDisplacement();
      ++this->m_Step;
    }
  }

  ~SimplexStepper() override
  {
    if (this->m_Data.IsNotNull())
    {
      for (auto it = this->m_Data->Begin(); it != this->m_Data->End(); ++it)
      {
        delete it.Value()->neighborSet;
        it.Value()->neighborSet = nullptr;
      }
    }
  }

protected:
  SimplexStepper() = default;
};

struct SimplexCase
{
  SimplexMeshType::Pointer                     mesh;
  SimplexModelType::GradientImageType::Pointer gradient;
};

/** Simplex mesh with about \a vertices vertices: dual of a geodesic sphere
 * with about vertices / 2 vertices (as many triangles as simplex vertices). */
SimplexMeshType::Pointer
MakeSimplexMesh(int64_t vertices)
{
  const auto triangleMesh =
    ToITKMesh<TriangleMeshType>(MakeGeodesicSphere(SphereFrequency(vertices / 2), InitialRadius, MeshCentre));
  using ConverterType = itk::TriangleMeshToSimplexMeshFilter<TriangleMeshType, SimplexMeshType>;
  auto converter = ConverterType::New();
  converter->SetInput(triangleMesh);
  converter->Update();
  SimplexMeshType::Pointer mesh = converter->GetOutput();
  mesh->DisconnectPipeline();
  return mesh;
}

SimplexModelType::GradientImageType::Pointer
SimplexGradient()
{
  static SimplexModelType::GradientImageType::Pointer gradient = [] {
    const ForceImageType * field = MeshForceImage();
    auto                   image = SimplexModelType::GradientImageType::New();
    image->CopyInformation(field);
    image->SetRegions(field->GetLargestPossibleRegion());
    image->Allocate();
    const auto *      in = field->GetBufferPointer();
    auto *            out = image->GetBufferPointer();
    const std::size_t n = field->GetBufferedRegion().GetNumberOfPixels();
    for (std::size_t i = 0; i < n; ++i)
    {
      for (unsigned int d = 0; d < 3; ++d)
      {
        out[i][d] = in[i][d];
      }
    }
    return image;
  }();
  return gradient;
}

void
BM_ITK_DeformableSimplexMesh3D(benchmark::State & state)
{
  const int64_t requested = state.range(0);
  // Cached: the filter moves its input's points in place, so a later run
  // continues where the previous one stopped, at the same cost per step.
  static std::map<int64_t, SimplexMeshType::Pointer> cache;
  SimplexMeshType::Pointer &                         mesh = cache[requested];
  if (mesh.IsNull())
  {
    mesh = MakeSimplexMesh(requested);
  }
  const auto         vertices = static_cast<int64_t>(mesh->GetNumberOfPoints());
  const unsigned int steps = requested >= 1000000 ? 1 : (requested >= 100000 ? 2 : 10);

  auto model = SimplexStepper::New();
  model->SetInput(mesh);
  model->SetGradient(SimplexGradient());
  model->SetAlpha(0.2);
  model->SetBeta(0.5);
  model->SetGamma(0.05);
  model->SetRigidity(1);
  model->Start();

  int64_t stepsRun = 0;
  for (auto _ : state)
  {
    model->Steps(steps);
    stepsRun += steps;
  }
  state.counters["vertices"] = static_cast<double>(vertices);
  state.counters["vertex_it/s"] =
    benchmark::Counter(static_cast<double>(vertices * stepsRun), benchmark::Counter::kIsRate);
  state.SetLabel("serial");
}

#ifdef EDM_BENCHMARK_WITH_VTK
// ---------------------------------------------------------------------------
// The seed's VTK loop: probe the force image at the points, warp the points
// by the probed vectors, feed the result back.
vtkSmartPointer<vtkImageData>
VTKForceImage()
{
  static vtkSmartPointer<vtkImageData> image = [] {
    const ForceImageType * field = MeshForceImage();
    const auto             size = field->GetLargestPossibleRegion().GetSize();
    auto                   output = vtkSmartPointer<vtkImageData>::New();
    output->SetDimensions(static_cast<int>(size[0]), static_cast<int>(size[1]), static_cast<int>(size[2]));
    output->SetOrigin(field->GetOrigin()[0], field->GetOrigin()[1], field->GetOrigin()[2]);
    output->SetSpacing(field->GetSpacing()[0], field->GetSpacing()[1], field->GetSpacing()[2]);
    vtkNew<vtkFloatArray> vectors;
    vectors->SetName("force");
    vectors->SetNumberOfComponents(3);
    const vtkIdType n = static_cast<vtkIdType>(field->GetBufferedRegion().GetNumberOfPixels());
    vectors->SetNumberOfTuples(n);
    const auto * in = field->GetBufferPointer();
    for (vtkIdType i = 0; i < n; ++i)
    {
      vectors->SetTypedTuple(i, in[i].GetDataPointer());
    }
    output->GetPointData()->SetVectors(vectors);
    return output;
  }();
  return image;
}

void
BM_VTK_ProbeWarp(benchmark::State & state)
{
  const int64_t requested = state.range(0);
  const auto    threads = static_cast<int>(state.range(1));
  const auto    sphere = MakeGeodesicSphere(SphereFrequency(requested), InitialRadius, MeshCentre);
  const auto    vertices = static_cast<vtkIdType>(sphere.points.size() / 3);
  vtkSMPTools::Initialize(threads);

  vtkNew<vtkPoints> points;
  points->SetDataTypeToFloat();
  points->SetNumberOfPoints(vertices);
  for (vtkIdType i = 0; i < vertices; ++i)
  {
    points->SetPoint(i, &sphere.points[3 * i]);
  }
  vtkNew<vtkCellArray> polys;
  for (std::size_t t = 0; t < sphere.triangles.size(); t += 3)
  {
    const vtkIdType ids[3] = { sphere.triangles[t], sphere.triangles[t + 1], sphere.triangles[t + 2] };
    polys->InsertNextCell(3, ids);
  }
  vtkNew<vtkPolyData> mesh;
  mesh->SetPoints(points);
  mesh->SetPolys(polys);

  vtkNew<vtkProbeFilter> probe;
  probe->SetInputData(mesh);
  probe->SetSourceData(VTKForceImage());
  vtkNew<vtkWarpVector> warp;
  warp->SetInputConnection(probe->GetOutputPort());
  warp->SetScaleFactor(0.5);

  const unsigned int steps = requested >= 1000000 ? 1 : (requested >= 100000 ? 5 : 20);
  int64_t            stepsRun = 0;
  for (auto _ : state)
  {
    for (unsigned int k = 0; k < steps; ++k)
    {
      warp->Update();
      mesh->SetPoints(warp->GetOutput()->GetPoints());
      mesh->Modified();
    }
    stepsRun += steps;
  }
  state.counters["vertices"] = static_cast<double>(vertices);
  state.counters["vertex_it/s"] =
    benchmark::Counter(static_cast<double>(vertices * stepsRun), benchmark::Counter::kIsRate);
  // Sanity check that the loop ran: mean distance moved from the initial sphere.
  double      moved = 0.0;
  vtkPoints * final = mesh->GetPoints();
  for (vtkIdType i = 0; i < vertices; ++i)
  {
    double p[3];
    final->GetPoint(i, p);
    moved += std::sqrt((p[0] - sphere.points[3 * i]) * (p[0] - sphere.points[3 * i]) +
                       (p[1] - sphere.points[3 * i + 1]) * (p[1] - sphere.points[3 * i + 1]) +
                       (p[2] - sphere.points[3 * i + 2]) * (p[2] - sphere.points[3 * i + 2]));
  }
  state.counters["moved"] = moved / static_cast<double>(vertices);
  state.SetLabel("external force only");
}
#endif

// ---------------------------------------------------------------------------
// Force field: ExternalForceImageFilter against two GradientImageFilter passes.
const ImageType *
ForceInput(unsigned int size)
{
  static std::map<unsigned int, ImageType::Pointer> cache;
  auto &                                            image = cache[size];
  if (image.IsNull())
  {
    image = MakePhantomImage(size);
  }
  return image;
}

void
BM_EDM_ExternalForce(benchmark::State & state)
{
  const auto        size = static_cast<unsigned int>(state.range(0));
  const auto        threads = static_cast<unsigned int>(state.range(1));
  ThreadScope       scope(threads);
  const ImageType * input = ForceInput(size);
  auto              forces = ForceFilterType::New();
  forces->SetInput(input);
  forces->SetSigma(1.0);
  forces->SetNumberOfWorkUnits(threads == 1 ? 1 : 4 * threads);
  for (auto _ : state)
  {
    forces->Modified();
    forces->Update();
  }
  const double voxels = static_cast<double>(size) * size * size;
  state.counters["voxel/s"] = benchmark::Counter(voxels * state.iterations(), benchmark::Counter::kIsRate);
}

void
BM_ITK_GradientTwice(benchmark::State & state)
{
  const auto        size = static_cast<unsigned int>(state.range(0));
  const auto        threads = static_cast<unsigned int>(state.range(1));
  ThreadScope       scope(threads);
  const ImageType * input = ForceInput(size);
  using GradientType = itk::GradientImageFilter<ImageType, float, float, ForceImageType>;
  auto first = GradientType::New();
  auto second = GradientType::New();
  first->SetInput(input);
  second->SetInput(input);
  first->SetNumberOfWorkUnits(threads == 1 ? 1 : 4 * threads);
  second->SetNumberOfWorkUnits(threads == 1 ? 1 : 4 * threads);
  for (auto _ : state)
  {
    first->Modified();
    first->Update();
    second->Modified();
    second->Update();
  }
  const double voxels = static_cast<double>(size) * size * size;
  state.counters["voxel/s"] = benchmark::Counter(voxels * state.iterations(), benchmark::Counter::kIsRate);
}

// ---------------------------------------------------------------------------
// Memory: heap bytes the filter holds between updates (coordinates, next
// coordinates, umbrella field, topology, diagnostics), per vertex, measured by
// deleting the filter and keeping its output. Also the peak during the first
// update beyond the input and the output.
void
BM_EDM_StateMemory(benchmark::State & state)
{
  const MeshType * input = ModelMesh(state.range(0));
  const auto       vertices = static_cast<int64_t>(input->GetNumberOfPoints());
  int64_t          held = 0;
  int64_t          peak = 0;
  for (auto _ : state)
  {
    MeshType::Pointer output;
    int64_t           beforeDeletion = 0;
    const int64_t     before = liveHeapBytes.load();
    {
      auto model = ModelType::New();
      model->SetInput(input);
      model->SetForceImage(MeshForceImage());
      model->SetElasticity(0.3);
      model->SetRigidity(0.1);
      model->SetNumberOfIterations(2);
      peakHeapBytes.store(liveHeapBytes.load());
      model->Update();
      peak = peakHeapBytes.load() - before;
      output = model->GetOutput();
      output->DisconnectPipeline();
      beforeDeletion = liveHeapBytes.load();
    }
    held = beforeDeletion - liveHeapBytes.load();
    const int64_t outputBytes = liveHeapBytes.load() - before;
    peak -= outputBytes;
  }
  stateBytesPerVertex = std::max(stateBytesPerVertex, held / vertices);
  peakBytesPerVertex = std::max(peakBytesPerVertex, peak / vertices);
  state.counters["vertices"] = static_cast<double>(vertices);
  state.counters["state_B/vertex"] = static_cast<double>(held) / vertices;
  state.counters["peak_B/vertex"] = static_cast<double>(peak) / vertices;
  if (held >= 200 * vertices)
  {
    state.SkipWithError("iteration state >= 200 bytes per vertex");
  }
}

void
MeshArguments(benchmark::internal::Benchmark * b, bool threaded)
{
  for (const int64_t vertices : { 10000, 100000, 1000000 })
  {
    for (const int64_t threads : { 1, 2 })
    {
      if (threaded || threads == 1)
      {
        b->Args({ vertices, threads });
      }
    }
  }
  b->ArgNames({ "vertices", "threads" })
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond)
    ->ComputeStatistics("max", Largest);
}

BENCHMARK(BM_EDM_DeformableMesh)->Apply([](benchmark::internal::Benchmark * b) { MeshArguments(b, true); });
BENCHMARK(BM_EDM_ExternalOnly)->Apply([](benchmark::internal::Benchmark * b) { MeshArguments(b, true); });
BENCHMARK(BM_EDM_SelfIntersection)
  ->ArgsProduct({ { 100000, 1000000 }, { 1, 2 } })
  ->ArgNames({ "vertices", "threads" })
  ->UseRealTime()
  ->Unit(benchmark::kMillisecond)
  ->ComputeStatistics("max", Largest);
BENCHMARK(BM_EDM_KernelPath)
  ->ArgsProduct({ { 100000 }, { 0, 1, 2 } })
  ->ArgNames({ "vertices", "path" })
  ->UseRealTime()
  ->Unit(benchmark::kMillisecond)
  ->ComputeStatistics("max", Largest);
BENCHMARK(BM_EDM_OneStepPerUpdate)
  ->Arg(100000)
  ->Arg(1000000)
  ->ArgName("vertices")
  ->UseRealTime()
  ->Unit(benchmark::kMillisecond)
  ->ComputeStatistics("max", Largest);
BENCHMARK(BM_EDM_Remeshing)
  ->ArgsProduct({ { 100000, 1000000 }, { 0, 1 } })
  ->ArgNames({ "vertices", "suppress_drift" })
  ->UseRealTime()
  ->Unit(benchmark::kMillisecond)
  ->ComputeStatistics("max", Largest);
BENCHMARK(BM_EDM_CollisionsAndRemeshing)
  ->ArgsProduct({ { 100000, 1000000 }, { 0, 1 } })
  ->ArgNames({ "vertices", "suppress_drift" })
  ->UseRealTime()
  ->Unit(benchmark::kMillisecond)
  ->ComputeStatistics("max", Largest);
BENCHMARK(BM_EDM_RegularSphereSource)
  ->Arg(1)
  ->Arg(0)
  ->ArgName("renumber")
  ->UseRealTime()
  ->Unit(benchmark::kMillisecond)
  ->ComputeStatistics("max", Largest);
BENCHMARK(BM_ITK_DeformableSimplexMesh3D)->Apply([](benchmark::internal::Benchmark * b) { MeshArguments(b, false); });
#ifdef EDM_BENCHMARK_WITH_VTK
BENCHMARK(BM_VTK_ProbeWarp)->Apply([](benchmark::internal::Benchmark * b) { MeshArguments(b, true); });
#endif
BENCHMARK(BM_EDM_ExternalForce)
  ->ArgsProduct({ { 128, 256 }, { 1, 2 } })
  ->ArgNames({ "size", "threads" })
  ->UseRealTime()
  ->Unit(benchmark::kMillisecond)
  ->ComputeStatistics("max", Largest);
BENCHMARK(BM_ITK_GradientTwice)
  ->ArgsProduct({ { 128, 256 }, { 1, 2 } })
  ->ArgNames({ "size", "threads" })
  ->UseRealTime()
  ->Unit(benchmark::kMillisecond)
  ->ComputeStatistics("max", Largest);
BENCHMARK(BM_EDM_StateMemory)
  ->Arg(100000)
  ->Arg(1000000)
  ->ArgName("vertices")
  ->Iterations(1)
  ->Unit(benchmark::kMillisecond);

/** Console output plus the rates kept for the summary. */
class SummaryReporter : public benchmark::ConsoleReporter
{
public:
  // Colours only on a terminal, so that redirected output stays plain text.
  SummaryReporter()
    : ConsoleReporter(isatty(STDOUT_FILENO) ? OO_ColorTabular : OO_Tabular)
  {}

  void
  ReportRuns(const std::vector<Run> & runs) override
  {
    for (const Run & run : runs)
    {
      const auto cpu = run.counters.find("cpu_ns/vertex_it");
      if (cpu != run.counters.end() && !run.error_occurred && run.run_type == Run::RT_Iteration)
      {
        summaryCPUTimes[run.run_name.str()] = cpu->second.value;
      }
      const auto settled = run.counters.find("settled_vertex_it/s");
      if (settled != run.counters.end() && !run.error_occurred && run.run_type == Run::RT_Iteration)
      {
        summarySettled[run.run_name.str()] = settled->second.value;
      }
      for (const char * counter : { "vertex_it/s", "voxel/s" })
      {
        const auto it = run.counters.find(counter);
        if (it == run.counters.end() || run.error_occurred)
        {
          continue;
        }
        if (run.run_type == Run::RT_Iteration)
        {
          summaryRates[run.run_name.str()] = it->second.value;
        }
        else if (run.aggregate_name == "max")
        {
          summaryBestRates[run.run_name.str()] = it->second.value;
        }
      }
    }
    ConsoleReporter::ReportRuns(runs);
  }
};

double
Rate(const std::string & name)
{
  const auto best = summaryBestRates.find(name);
  if (best != summaryBestRates.end())
  {
    return best->second;
  }
  const auto it = summaryRates.find(name);
  return it == summaryRates.end() ? 0.0 : it->second;
}

double
Settled(const std::string & name)
{
  const auto it = summarySettled.find(name);
  return it == summarySettled.end() ? 0.0 : it->second;
}

double
CPUTime(const std::string & name)
{
  const auto it = summaryCPUTimes.find(name);
  return it == summaryCPUTimes.end() ? 0.0 : it->second;
}

void
PrintRatio(const char * what, double numerator, double denominator)
{
  if (numerator > 0.0 && denominator > 0.0)
  {
    std::printf("  %-52s %8.2f\n", what, numerator / denominator);
  }
}

void
PrintSummary()
{
  std::printf("\nSummary (M = millions per second; best of the repetitions when there are several)\n");
  for (const char * size : { "10000", "100000", "1000000" })
  {
    const std::string suffix = std::string("/vertices:") + size;
    const double      ours1 = Rate("BM_EDM_DeformableMesh" + suffix + "/threads:1/real_time");
    const double      ours2 = Rate("BM_EDM_DeformableMesh" + suffix + "/threads:2/real_time");
    const double      simplex = Rate("BM_ITK_DeformableSimplexMesh3D" + suffix + "/threads:1/real_time");
    const double      vtk1 = Rate("BM_VTK_ProbeWarp" + suffix + "/threads:1/real_time");
    const double      vtk2 = Rate("BM_VTK_ProbeWarp" + suffix + "/threads:2/real_time");
    const double      external2 = Rate("BM_EDM_ExternalOnly" + suffix + "/threads:2/real_time");
    if (ours1 + ours2 + simplex + vtk1 + vtk2 + external2 == 0.0)
    {
      continue;
    }
    std::printf("%s vertices: vertex-iterations/s  EDM 1 thread %.2f M, 2 threads %.2f M; ITK simplex %.2f M; "
                "VTK probe+warp 1 thread %.2f M, 2 threads %.2f M; EDM external only, 2 threads %.2f M\n",
                size,
                ours1 * 1e-6,
                ours2 * 1e-6,
                simplex * 1e-6,
                vtk1 * 1e-6,
                vtk2 * 1e-6,
                external2 * 1e-6);
    PrintRatio("EDM 2 threads / 1 thread", ours2, ours1);
    PrintRatio("EDM 2 threads / ITK DeformableSimplexMesh3D", ours2, simplex);
    PrintRatio("EDM 2 threads / VTK probe+warp 2 threads", ours2, vtk2);
    PrintRatio("EDM 1 thread / ITK DeformableSimplexMesh3D", ours1, simplex);
    PrintRatio("EDM 1 thread / VTK probe+warp 1 thread", ours1, vtk1);
    PrintRatio("EDM external only / VTK probe+warp, 2 threads", external2, vtk2);
  }
  {
    const double avx2 = Rate("BM_EDM_KernelPath/vertices:100000/path:0/real_time");
    const double sse2 = Rate("BM_EDM_KernelPath/vertices:100000/path:1/real_time");
    const double portable = Rate("BM_EDM_KernelPath/vertices:100000/path:2/real_time");
    if (avx2 + sse2 + portable > 0.0)
    {
      std::printf("kernel paths, 100000 vertices, 1 thread (default: %s): AVX2+FMA %.2f M, SSE2 %.2f M, portable "
                  "%.2f M vertex-iterations/s\n",
                  itk::DeformableMeshFilterDetail::KernelPathName(itk::DeformableMeshFilterDetail::GetKernelPath()),
                  avx2 * 1e-6,
                  sse2 * 1e-6,
                  portable * 1e-6);
      PrintRatio("AVX2+FMA / SSE2", avx2, sse2);
      PrintRatio("SSE2 / portable", sse2, portable);
    }
  }
  {
    const double renumbered = Rate("BM_EDM_RegularSphereSource/renumber:1/real_time");
    const double asInput = Rate("BM_EDM_RegularSphereSource/renumber:0/real_time");
    // The remeshing rows, with the whole force (suppress_drift:0) and with
    // the tangential drift suppressed, the filter's default (suppress_drift:1).
    const auto remeshingSummary = [](const char * benchmark, const char * what) {
      for (const char * drift : { "0", "1" })
      {
        const std::string row100k = std::string(benchmark) + "/vertices:100000/suppress_drift:" + drift + "/real_time";
        const std::string row1M = std::string(benchmark) + "/vertices:1000000/suppress_drift:" + drift + "/real_time";
        const double      rate100k = Rate(row100k);
        const double      rate1M = Rate(row1M);
        if (rate100k + rate1M > 0.0)
        {
          std::printf("%s%s, 2 threads: 100000 vertices %.2f M, 1000000 vertices %.2f M vertex-iterations/s (issue "
                      "15 target: 25 M); CPU time per vertex-iteration %.0f ns and %.0f ns; the last half of the "
                      "updates (the surface settled): %.2f M and %.2f M\n",
                      what,
                      drift[0] == '1' ? ", tangential drift suppressed (the default)" : ", whole force",
                      rate100k * 1e-6,
                      rate1M * 1e-6,
                      CPUTime(row100k),
                      CPUTime(row1M),
                      Settled(row100k) * 1e-6,
                      Settled(row1M) * 1e-6);
        }
      }
    };
    remeshingSummary("BM_EDM_Remeshing", "remeshing every 10 iterations");
    const double collision100k = Rate("BM_EDM_SelfIntersection/vertices:100000/threads:2/real_time");
    const double collision1M = Rate("BM_EDM_SelfIntersection/vertices:1000000/threads:2/real_time");
    if (collision100k + collision1M > 0.0)
    {
      std::printf("collision test every iteration, 2 threads: 100000 vertices %.2f M, 1000000 vertices %.2f M "
                  "vertex-iterations/s (issue 15 target: 25 M); CPU time per vertex-iteration %.0f ns and %.0f ns\n",
                  collision100k * 1e-6,
                  collision1M * 1e-6,
                  CPUTime("BM_EDM_SelfIntersection/vertices:100000/threads:2/real_time"),
                  CPUTime("BM_EDM_SelfIntersection/vertices:1000000/threads:2/real_time"));
    }
    remeshingSummary("BM_EDM_CollisionsAndRemeshing",
                     "remeshing every 10 iterations with the collision test every iteration");
    if (renumbered + asInput > 0.0)
    {
      std::printf("RegularSphereMeshSource, 262146 vertices, 2 threads: renumbered %.2f M, input numbering %.2f M "
                  "vertex-iterations/s (issue 15 target: 50 M); CPU time per vertex-iteration %.1f ns and %.1f ns "
                  "(geodesic sphere, 100000 vertices, 2 threads: %.1f ns)\n",
                  renumbered * 1e-6,
                  asInput * 1e-6,
                  CPUTime("BM_EDM_RegularSphereSource/renumber:1/real_time"),
                  CPUTime("BM_EDM_RegularSphereSource/renumber:0/real_time"),
                  CPUTime("BM_EDM_DeformableMesh/vertices:100000/threads:2/real_time"));
    }
  }
  for (const char * size : { "128", "256" })
  {
    for (const char * threads : { "1", "2" })
    {
      const std::string suffix = std::string("/size:") + size + "/threads:" + threads + "/real_time";
      const double      ours = Rate(std::string("BM_EDM_ExternalForce") + suffix);
      const double      gradient = Rate(std::string("BM_ITK_GradientTwice") + suffix);
      if (ours > 0.0 || gradient > 0.0)
      {
        std::printf("force field %s^3, %s thread(s): ExternalForce %.1f M voxel/s, GradientImageFilter x2 %.1f M "
                    "voxel/s, ratio %.2f\n",
                    size,
                    threads,
                    ours * 1e-6,
                    gradient * 1e-6,
                    gradient > 0.0 ? ours / gradient : 0.0);
      }
    }
  }
  if (stateBytesPerVertex >= 0)
  {
    std::printf("iteration state (largest over the sizes): %lld bytes per vertex held between updates (limit 200), "
                "%lld at the peak of the "
                "first update beyond input and output\n",
                static_cast<long long>(stateBytesPerVertex),
                static_cast<long long>(peakBytesPerVertex));
  }
  std::ifstream load("/proc/loadavg");
  std::string   loadAverage;
  std::getline(load, loadAverage);
  std::printf("load average at the end: %s\n", loadAverage.c_str());
}

// On a virtual machine, the first write to a page of memory that the guest
// has never used costs a fault in the host as well, several times the
// guest's own: the 1M-vertex remeshing rows, which reach a new peak of
// memory at each remeshing, ran 1.4 to 1.6 times slower than after the
// guest had used that memory once (docs/performance.md). Before the benchmarks, the program
// writes to EDM_BENCHMARK_WARM_MB megabytes (default 2048, the 1M rows
// peak at 1.3 GB; 0: none) and frees them, so that the rows do not time the
// host's first use of the guest's memory.
void
WarmMemory()
{
  const char *      text = std::getenv("EDM_BENCHMARK_WARM_MB");
  const std::size_t megabytes = text != nullptr ? std::strtoull(text, nullptr, 10) : 2048;
  if (megabytes == 0)
  {
    return;
  }
  const std::size_t bytes = megabytes << 20;
  auto *            memory = static_cast<volatile char *>(std::malloc(bytes));
  if (memory == nullptr)
  {
    return;
  }
  for (std::size_t i = 0; i < bytes; i += 4096)
  {
    memory[i] = 1;
  }
  std::free(const_cast<char *>(memory));
}
} // namespace

int
main(int argc, char ** argv)
{
  benchmark::Initialize(&argc, argv);
  WarmMemory();
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
  {
    return 1;
  }
  SummaryReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  PrintSummary();
  return stateBytesPerVertex >= 200 ? EXIT_FAILURE : EXIT_SUCCESS;
}
