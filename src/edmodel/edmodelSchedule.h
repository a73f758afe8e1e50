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
#ifndef edmodelSchedule_h
#define edmodelSchedule_h

// What 'edmodel segment' does the same way on 3-D surfaces
// (edmodelPipeline.cxx) and 2-D contours (edmodelContour.cxx), written once
// over the image and filter types: the image's frame (smallest spacing,
// inside test, bounds), and one level of the coarse-to-fine schedule (the
// DeformableMeshFilter's parameters for the level, its run with progress and
// snapshots, what the next level inherits). The callers own the mesh
// (subdivision, conversions) and the decision to stop refining.

#include "edmodelOptions.h"
#include "edmodelProgress.h"

#include "itkCommand.h"
#include "itkDeformableMeshFilter.h"

#include "itkContinuousIndex.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <iomanip>
#include <sstream>
#include <string>

namespace edm
{

inline std::string
Format(double value, int precision = 3)
{
  std::ostringstream stream;
  stream << std::setprecision(precision) << value;
  return stream.str();
}

// --- The image's frame ------------------------------------------------------

template <typename TImage>
double
SmallestSpacing(const TImage * image)
{
  const auto & spacing = image->GetSpacing();
  double       smallest = spacing[0];
  for (unsigned int k = 1; k < TImage::ImageDimension; ++k)
  {
    smallest = std::min(smallest, spacing[k]);
  }
  return smallest;
}

/** True when p falls within the image's voxels (half a voxel beyond the first
 * and last voxel centres, the domain where the force is sampled), widened by
 * margin voxels on each side. */
template <typename TImage, typename TPoint>
bool
IsInsideImage(const TImage * image, const TPoint & p, double margin = 0.0)
{
  constexpr unsigned int                  Dimension = TImage::ImageDimension;
  itk::ContinuousIndex<double, Dimension> index;
  static_cast<void>(image->TransformPhysicalPointToContinuousIndex(p, index)); // the region test follows
  const auto & region = image->GetLargestPossibleRegion();
  for (unsigned int k = 0; k < Dimension; ++k)
  {
    const double low = static_cast<double>(region.GetIndex()[k]) - 0.5 - margin;
    if (!(index[k] >= low && index[k] <= low + static_cast<double>(region.GetSize()[k]) + 2.0 * margin))
    {
      return false;
    }
  }
  return true;
}

/** The physical bounding box of the image's voxels, for messages:
 * "x a to b, y c to d[, z e to f] mm". */
template <typename TImage>
std::string
DescribeBounds(const TImage * image)
{
  constexpr unsigned int Dimension = TImage::ImageDimension;
  double                 low[Dimension];
  double                 high[Dimension];
  std::fill(low, low + Dimension, 1e300);
  std::fill(high, high + Dimension, -1e300);
  const auto region = image->GetLargestPossibleRegion();
  for (unsigned int corner = 0; corner < (1u << Dimension); ++corner)
  {
    itk::ContinuousIndex<double, Dimension> index;
    for (unsigned int k = 0; k < Dimension; ++k)
    {
      index[k] = region.GetIndex()[k] - 0.5 + ((corner >> k) & 1 ? region.GetSize()[k] : 0);
    }
    typename TImage::PointType p;
    image->TransformContinuousIndexToPhysicalPoint(index, p);
    for (unsigned int k = 0; k < Dimension; ++k)
    {
      low[k] = std::min(low[k], p[k]);
      high[k] = std::max(high[k], p[k]);
    }
  }
  std::string text;
  for (unsigned int k = 0; k < Dimension; ++k)
  {
    text += std::string(k > 0 ? ", " : "") + "xyz"[k] + " " + Format(low[k], 6) + " to " + Format(high[k], 6);
  }
  return text + " mm";
}

// --- The force field ----------------------------------------------------------

/** The sigma (mm) of the force field: --sigma, or SigmaInVoxels voxels of the
 * smallest spacing. */
template <typename TImage>
double
ForceSigma(const TImage * image, const SegmentOptions & o)
{
  return o.sigma >= 0.0 ? o.sigma : defaults::SigmaInVoxels * SmallestSpacing(image);
}

/** The largest external displacement per iteration (mm): --scale, or
 * ScaleOverSigma times sigma (times the smallest spacing when sigma is 0). */
template <typename TImage>
double
ForceScale(const TImage * image, const SegmentOptions & o)
{
  const double sigma = ForceSigma(image, o);
  return o.scale >= 0.0 ? o.scale : defaults::ScaleOverSigma * (sigma > 0.0 ? sigma : SmallestSpacing(image));
}

/** Runs an ExternalForceImageFilter on image with the options' force
 * settings, under the progress's "force field" stage; throws Error. With
 * `smoothed` set, the image is already smoothed by the force's Gaussian
 * (SmoothWithSampledGaussian, the filter's own smoothing): the filter does
 * not smooth it again. */
template <typename TForceFilter>
typename TForceFilter::OutputImageType::Pointer
ComputeForceField(const typename TForceFilter::InputImageType * image,
                  const SegmentOptions &                        o,
                  Progress &                                    progress,
                  bool                                          smoothed = false)
{
  const double sigma = ForceSigma(image, o);
  auto         force = TForceFilter::New();
  force->SetInput(image);
  force->SetSigma(smoothed ? 0.0 : sigma);
  force->SetNormalizeForces(o.normalizeForces);
  force->SetUseGradientVectorFlow(o.gradientVectorFlow);
  force->SetGradientVectorFlowRegularization(o.gradientVectorFlowRegularization);
  force->SetGradientVectorFlowIterations(o.gradientVectorFlowIterations);
  progress.Start("force field");
  if (progress.IsEnabled())
  {
    force->AddObserver(itk::ProgressEvent(),
                       [&](const itk::EventObject &) { progress.Update(force->GetProgress(), ""); });
  }
  const auto start = std::chrono::steady_clock::now();
  try
  {
    force->Update();
  }
  catch (const itk::ExceptionObject & exception)
  {
    throw Error("force field: " + OneLine(exception.GetDescription()));
  }
  if (progress.IsEnabled())
  {
    progress.Finish("sigma " + Format(sigma) + " mm" + (o.gradientVectorFlow ? ", gradient vector flow" : "") +
                    (o.normalizeForces ? ", normalised" : ", not normalised") + " (" +
                    Format(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2) + " s)");
  }
  typename TForceFilter::OutputImageType::Pointer field = force->GetOutput();
  field->DisconnectPipeline();
  return field;
}

// --- Timing ------------------------------------------------------------------

/** --repeat N: calls compute(progress, true) (the run whose result is used:
 * progress and snapshots), then compute(quiet, false) N - 1 more times with
 * a silent progress, and notes the fastest and the first run's wall-clock
 * time. A run in a fresh process pays for its first use of the code and the
 * memory (page faults, lazy binding); the later runs show the computation
 * alone, as a library call timed in a loop does. */
template <typename TCompute>
auto
RunRepeated(const SegmentOptions & o, Progress & progress, const TCompute & compute)
{
  using Clock = std::chrono::steady_clock;
  const auto   start = Clock::now();
  auto         result = compute(progress, true);
  const double first = std::chrono::duration<double>(Clock::now() - start).count();
  if (o.repeat <= 1)
  {
    return result;
  }
  double   fastest = first;
  Progress quiet(true);
  for (unsigned int run = 1; run < o.repeat; ++run)
  {
    const auto again = Clock::now();
    static_cast<void>(compute(quiet, false));
    fastest = std::min(fastest, std::chrono::duration<double>(Clock::now() - again).count());
  }
  progress.Note("--repeat " + std::to_string(o.repeat) + ": force field and deformation in " + Format(fastest, 3) +
                " s at best (the first run " + Format(first, 3) + " s)");
  return result;
}

// --- One level of the coarse-to-fine schedule -------------------------------

/** The schedule's settings that hold for every level, resolved from the
 * options and the image's spacing by the caller. */
struct LevelSchedule
{
  double       scale{ 0.0 };              // mm per iteration of the external force
  double       regionWeight{ 0.0 };       // mm per iteration, 0: no region force
  double       regionSigma{ 0.0 };        // mm, the refined levels' smoothing
  double       edgeSearchWeight{ 0.0 };   // mm per iteration, 0: off
  double       edgeSearchDistance{ 0.0 }; // mm
  double       edgeLength{ 0.0 };         // mm, the mean edge the refinement aims at
  bool         tangentialElasticity{ false };
  bool         convergenceAlongNormals{ false }; // the convergence test on the displacements' normal parts
  double       captureRegionWeightFactor{ 1.0 }; // the capture level's region weight over the others'
  double       captureRegionSigmaFactor{ defaults::CoarseRegionSigmaFactor }; // the same for the region sigma
  const char * pointsWord{ "vertices" }; // what the progress calls the mesh's points
  const char * initialWhat{ "surface" }; // "surface" or "contour", for the notes
};

/** What a level hands to the next: the object's intensity model (estimated
 * once, by the first level with the region force, inside the initial mesh),
 * and the totals reported at the end. */
struct LevelState
{
  bool               haveModel{ false };
  double             model[2]{ 0.0, 0.0 }; // median and spread
  itk::SizeValueType iterations{ 0 };      // over all levels so far
  bool               converged{ false };   // of the last level run
  double             lastMaximumDisplacement{ 0.0 };
};

/** Sets the parameters of level `stage` (0 the first) on a filter whose
 * input, force image and intensity image the caller has set. `last` says
 * that no refined level follows (a single level, or refinement off);
 * `meanEdgeLength` is the level's input's mean edge in mm. */
template <typename TFilter>
void
ConfigureLevel(TFilter *              deform,
               const SegmentOptions & o,
               const LevelSchedule &  s,
               const LevelState &     state,
               unsigned int           stage,
               bool                   last,
               double                 meanEdgeLength)
{
  deform->SetScaleFactor(s.scale);
  // The capture level (the first of several) has the schedule's own internal
  // weights; --elasticity and --rigidity shape the refined levels, which make
  // the result. A stiffer capture mesh (1 026 points, edges of about 5 mm on
  // a 40 mm sphere) cannot fill two lobes at once and settles in the cleft
  // between them (ch2, elasticity 0.6: the interhemispheric fissure, Dice
  // 0.951), a slacker one folds (0.125: 0.949); the refined levels then keep
  // the fold.
  const bool capture = stage == 0 && !last;
  deform->SetElasticity(capture ? defaults::Elasticity : o.elasticity);
  deform->SetTangentialElasticity(s.tangentialElasticity);
  deform->SetRigidity(capture ? defaults::Rigidity : o.rigidity);
  deform->SetBalloon(o.balloon);
  // On refined levels finer than FineLevelEdgeLengths x --edge-length the
  // region force is weighted by (h / that length)^2, h the level's mean edge:
  // the membrane force of a mesh of edge h bends the surface by about
  // a h^2 kappa / 4 per iteration (a h^2 kappa / 2 on a contour), so the
  // curvature at which it balances the region force stays that of the
  // coarser level (the surface does not creep into sulci and fissures as its
  // mesh is refined), and the finest level converges within its iterations.
  const double levelEdge = meanEdgeLength / (defaults::FineLevelEdgeLengths * s.edgeLength);
  // The capture level's region force may be faster and see the image
  // smoothed more (LevelSchedule's capture factors).
  deform->SetRegionWeight(capture      ? s.captureRegionWeightFactor * s.regionWeight
                          : stage == 0 ? s.regionWeight
                                       : s.regionWeight * std::min(1.0, levelEdge * levelEdge));
  deform->SetRegionSigma(capture ? s.captureRegionSigmaFactor * s.regionSigma : s.regionSigma);
  deform->SetIntensityTolerance(o.intensityTolerance);
  deform->SetEdgeSearchWeight(s.edgeSearchWeight);
  deform->SetEdgeSearchDistance(s.edgeSearchDistance);
  if (o.hasObjectRange)
  {
    deform->SetObjectIntensityRange(o.objectRange[0], o.objectRange[1], 0.1 * (o.objectRange[1] - o.objectRange[0]));
  }
  else if (state.haveModel)
  {
    deform->SetObjectIntensityStatistics(state.model[0], state.model[1]);
  }
  else
  {
    deform->EstimateObjectIntensityRangeOn();
  }
  deform->SetFixedBoundary(o.fixedBoundary);
  deform->SetDampOscillations(o.dampOscillations);
  deform->SetMaximumStepLength(o.maximumStepLength);
  deform->SetConvergenceTolerance(o.convergenceTolerance);
  deform->SetConvergenceWindow(o.convergenceWindow);
  deform->SetConvergenceFraction(o.convergenceFraction);
  deform->SetConvergenceAlongNormals(s.convergenceAlongNormals);
  // The capture level runs until it converges, up to CaptureIterations (or
  // --iterations when larger): from a small sphere it travels far, and its
  // front slows down as it fills narrow lobes (ch2: 700 iterations), so that
  // a cap of 500 would stop it anywhere along the way and the result would
  // depend on --iterations.
  deform->SetNumberOfIterations(capture && o.iterations > 0 ? std::max(o.iterations, defaults::CaptureIterations)
                                                            : o.iterations);
}

/** Runs a configured level: progress ("deforming", with the level's number
 * of points), snapshots every --snapshot-every iterations and at the end
 * (`snapshot(iteration)` is called with the total iteration count; the
 * caller reads the filter's output), the intensity model's notes; updates
 * `state`. With a `checkpoint`, the level runs in updates of `checkEvery`
 * iterations (the filter's continuation, IterateFromZero off) and
 * checkpoint() is called after each (the output then holds the mesh of that
 * iteration); when it returns true the level stops there and RunLevel
 * returns true. Throws Error when the filter throws. */
template <typename TFilter>
bool
RunLevel(TFilter *                                       deform,
         const SegmentOptions &                          o,
         const LevelSchedule &                           s,
         Progress &                                      progress,
         itk::SizeValueType                              numberOfPoints,
         LevelState &                                    state,
         const std::function<void(itk::SizeValueType)> & snapshot,
         itk::SizeValueType                              checkEvery = 0,
         const std::function<bool()> &                   checkpoint = std::function<bool()>())
{
  const itk::SizeValueType cap = deform->GetNumberOfIterations();
  const std::string        level = std::to_string(numberOfPoints) + " points";
  const auto               iterationsBefore = state.iterations;
  progress.Start("deforming");
  const auto start = std::chrono::steady_clock::now();
  // Only a progress that draws observes the filter: an observer of
  // ProgressEvent makes the filter compute its per-vertex diagnostics at
  // every iteration, a tenth of a small contour's computation.
  const auto progressTag =
    !progress.IsEnabled() ? 0UL : deform->AddObserver(itk::ProgressEvent(), [&](const itk::EventObject &) {
      const auto   total = cap;
      const auto   current = deform->GetCurrentIteration();
      const double fraction = total > 0 ? static_cast<double>(current) / total : 1.0;
      if (!progress.Due(fraction))
      {
        return;
      }
      progress.Update(fraction,
                      level + ", iteration " + std::to_string(current) + "/" + std::to_string(total) +
                        ", largest step " + Format(deform->GetLastMaximumDisplacement()) + " mm");
    });
  unsigned long snapshotTag = 0;
  if (snapshot)
  {
    snapshotTag = deform->AddObserver(itk::IterationEvent(), [&](const itk::EventObject &) {
      if (deform->GetCurrentIteration() % o.snapshotEvery == 0)
      {
        snapshot(iterationsBefore + deform->GetCurrentIteration());
      }
    });
  }
  const auto removeObservers = [&]() {
    if (progress.IsEnabled())
    {
      deform->RemoveObserver(progressTag);
    }
    if (snapshot)
    {
      deform->RemoveObserver(snapshotTag);
    }
  };
  bool stopped = false;
  try
  {
    if (checkpoint && checkEvery > 0)
    {
      // A new input resets the filter at its first update; the later ones
      // continue where it stopped.
      const bool fromZero = deform->GetIterateFromZero();
      deform->IterateFromZeroOff();
      for (itk::SizeValueType target = std::min(cap, checkEvery);; target = std::min(cap, target + checkEvery))
      {
        deform->SetNumberOfIterations(target);
        deform->Update();
        if (checkpoint())
        {
          stopped = true;
          break;
        }
        if (deform->GetConverged() || deform->GetCurrentIteration() < target || target >= cap)
        {
          break;
        }
      }
      deform->SetIterateFromZero(fromZero);
    }
    else
    {
      deform->Update();
    }
  }
  catch (const itk::ExceptionObject & exception)
  {
    removeObservers();
    throw Error("deformation: " + OneLine(exception.GetDescription()));
  }
  removeObservers();
  if (deform->GetRegionWeight() > 0.0 && !o.hasObjectRange && !state.haveModel)
  {
    state.haveModel = true;
    state.model[0] = deform->GetObjectIntensityMedian();
    state.model[1] = deform->GetObjectIntensitySpread();
    if (progress.IsEnabled())
    {
      progress.Note("region force: object intensity median " + Format(state.model[0], 4) + ", spread " +
                    Format(state.model[1], 3) + " (estimated inside the initial " + s.initialWhat + ")");
    }
  }
  if (deform->GetRegionWeight() > 0.0 && progress.IsEnabled())
  {
    progress.Note("region force: intensity range [" + Format(deform->GetObjectIntensityLower(), 4) + ", " +
                  Format(deform->GetObjectIntensityUpper(), 4) + "], transition width " +
                  Format(deform->GetObjectIntensityWidth(), 3));
  }
  if (snapshot && deform->GetCurrentIteration() % o.snapshotEvery != 0)
  {
    snapshot(iterationsBefore + deform->GetCurrentIteration());
  }
  state.iterations += deform->GetCurrentIteration();
  state.converged = deform->GetConverged();
  state.lastMaximumDisplacement = deform->GetLastMaximumDisplacement();
  if (!progress.IsEnabled())
  {
    // The summary's text (a tenth of a small contour's set-up) is not built.
    return stopped;
  }
  const double      seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string quiet =
    o.convergenceFraction > 0.0
      ? "at most " +
          std::to_string(static_cast<unsigned long long>(o.convergenceFraction * static_cast<double>(numberOfPoints))) +
          " " + s.pointsWord + " moving" + (s.convergenceAlongNormals ? " along their normals" : "") + " by "
      : std::string(s.convergenceAlongNormals ? "largest step along the normals below " : "largest step below ");
  progress.Finish(std::to_string(deform->GetCurrentIteration()) + " iterations on " + level + ", " +
                  (stopped           ? std::string("stopped to repair the contour")
                   : state.converged ? "converged (" + quiet + Format(deform->GetConvergenceTolerance()) + " mm for " +
                                         std::to_string(o.convergenceWindow) + " iterations)"
                                     : std::string("iteration cap reached")) +
                  ", last largest step " + Format(state.lastMaximumDisplacement) + " mm (" + Format(seconds, 2) +
                  " s)");
  return stopped;
}

} // namespace edm

#endif
