
// The subcommands: the ITK pipeline ExternalForceImageFilter ->
// DeformableMeshFilter, with progress reporting. No deformation maths here:
// the filters do it.

#include "itkSurfaceCollision.h"
#include "edmodelIO.h"
#include "edmodelOptions.h"
#include "edmodelProgress.h"
#include "edmodelSchedule.h"

#include "itkDeformableMeshFilter.h"
#include "itkEllipsoidPhantom.h"
#include "itkExternalForceImageFilter.h"
#include "itkMultiThreaderBase.h"
#include "itkVersion.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <unistd.h>

namespace edm
{
namespace
{

using ForceFilterType = itk::ExternalForceImageFilter<ImageType, ForceImageType>;
using DeformFilterType = itk::DeformableMeshFilter<MeshType, ForceImageType>;

std::string
FormatPoint(const double * p, unsigned int n)
{
  std::string text = "(";
  for (unsigned int k = 0; k < n; ++k)
  {
    text += (k == 0 ? "" : ", ") + Format(p[k], 6);
  }
  return text + ")";
}

MeshType::Pointer
MakeInitialSphere(const ImageType * image, const SegmentOptions & options)
{
  MeshType::PointType center;
  double              radius = 0.0;
  if (options.hasInitSphere)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      center[k] = options.sphere[k];
    }
    radius = options.sphere[3];
    if (!IsInsideImage(image, center))
    {
      throw Error("--init-sphere: the centre " + FormatPoint(options.sphere, 3) + " is outside the image (" +
                  DescribeBounds(image) + ")");
    }
  }
  else
  {
    const auto &                    region = image->GetLargestPossibleRegion();
    itk::ContinuousIndex<double, 3> middle;
    double                          smallestExtent = 1e300;
    for (unsigned int k = 0; k < 3; ++k)
    {
      middle[k] = region.GetIndex()[k] + 0.5 * (static_cast<double>(region.GetSize()[k]) - 1.0);
      smallestExtent = std::min(smallestExtent, region.GetSize()[k] * image->GetSpacing()[k]);
    }
    image->TransformContinuousIndexToPhysicalPoint(middle, center);
    radius = defaults::SphereRadiusOverExtent * smallestExtent;
  }
  MeshType::Pointer sphere = itk::MakeSphereMesh<MeshType>(center, radius, options.sphereResolution);
  for (auto it = sphere->GetPoints()->Begin(); it != sphere->GetPoints()->End(); ++it)
  {
    if (!IsInsideImage(image, it.Value()))
    {
      const double c[3] = { center[0], center[1], center[2] };
      throw Error("--init-sphere: the sphere of centre " + FormatPoint(c, 3) + " and radius " + Format(radius, 6) +
                  " mm extends outside the image (" + DescribeBounds(image) + ")");
    }
  }
  return sphere;
}

void
CheckInitialMesh(const ImageType * image, const MeshType * mesh, const std::string & path, Progress & progress)
{
  size_t outside = 0;
  for (auto it = mesh->GetPoints()->Begin(); it != mesh->GetPoints()->End(); ++it)
  {
    outside += IsInsideImage(image, it.Value()) ? 0 : 1;
  }
  if (outside == mesh->GetNumberOfPoints())
  {
    throw Error("--init-mesh: mesh '" + path + "' lies outside the image (" + DescribeBounds(image) + ")");
  }
  if (outside > 0)
  {
    progress.Note("warning: " + std::to_string(outside) + " of " + std::to_string(mesh->GetNumberOfPoints()) +
                  " points of the initial mesh are outside the image and feel no external force");
  }
}

/** True when every cell of the mesh is a triangle: only such meshes are
 * refined (SubdivideTriangles() would drop other cells). */
bool
HasOnlyTriangles(const MeshType * mesh)
{
  for (auto cell = mesh->GetCells()->Begin(); cell != mesh->GetCells()->End(); ++cell)
  {
    if (cell.Value()->GetNumberOfPoints() != 3)
    {
      return false;
    }
  }
  return mesh->GetNumberOfCells() > 0;
}

/** Mean length of the edges of the mesh's triangles (each edge counted once
 * per triangle side), physical units. */
double
MeanEdgeLength(const MeshType * mesh)
{
  double sum = 0.0;
  size_t count = 0;
  for (auto cell = mesh->GetCells()->Begin(); cell != mesh->GetCells()->End(); ++cell)
  {
    const auto * c = cell.Value();
    if (c->GetNumberOfPoints() != 3)
    {
      continue;
    }
    const auto * ids = c->GetPointIds();
    for (unsigned int k = 0; k < 3; ++k)
    {
      sum += mesh->GetPoint(ids[k]).EuclideanDistanceTo(mesh->GetPoint(ids[(k + 1) % 3]));
      ++count;
    }
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

/** Each triangle split into four at the midpoints of its edges (orientation
 * kept); other cells are dropped. */
MeshType::Pointer
SubdivideTriangles(const MeshType * mesh)
{
  using CellType = MeshType::CellType;
  using TriangleType = itk::TriangleCell<CellType>;
  auto output = MeshType::New();
  auto points = MeshType::PointsContainer::New();
  points->Reserve(mesh->GetNumberOfPoints());
  for (auto it = mesh->GetPoints()->Begin(); it != mesh->GetPoints()->End(); ++it)
  {
    points->SetElement(it.Index(), it.Value());
  }
  itk::IdentifierType                                                                next = mesh->GetNumberOfPoints();
  std::map<std::pair<itk::IdentifierType, itk::IdentifierType>, itk::IdentifierType> midpoints;
  const auto midpoint = [&](itk::IdentifierType a, itk::IdentifierType b) {
    const auto key = std::make_pair(std::min(a, b), std::max(a, b));
    const auto found = midpoints.find(key);
    if (found != midpoints.end())
    {
      return found->second;
    }
    MeshType::PointType p;
    const auto &        pa = points->ElementAt(a);
    const auto &        pb = points->ElementAt(b);
    for (unsigned int k = 0; k < 3; ++k)
    {
      p[k] = 0.5 * (pa[k] + pb[k]);
    }
    points->InsertElement(next, p);
    midpoints.emplace(key, next);
    return next++;
  };
  output->SetPoints(points);
  itk::IdentifierType cellId = 0;
  const auto          addTriangle = [&](itk::IdentifierType a, itk::IdentifierType b, itk::IdentifierType c) {
    CellType::CellAutoPointer cell;
    cell.TakeOwnership(new TriangleType);
    cell->SetPointId(0, a);
    cell->SetPointId(1, b);
    cell->SetPointId(2, c);
    output->SetCell(cellId++, cell);
  };
  for (auto cell = mesh->GetCells()->Begin(); cell != mesh->GetCells()->End(); ++cell)
  {
    const auto * c = cell.Value();
    if (c->GetNumberOfPoints() != 3)
    {
      continue;
    }
    const auto * ids = c->GetPointIds();
    const auto   ab = midpoint(ids[0], ids[1]);
    const auto   bc = midpoint(ids[1], ids[2]);
    const auto   ca = midpoint(ids[2], ids[0]);
    addTriangle(ids[0], ab, ca);
    addTriangle(ab, ids[1], bc);
    addTriangle(ca, bc, ids[2]);
    addTriangle(ab, bc, ca);
  }
  return output;
}

/** Volume enclosed by the mesh's triangles (absolute value of the signed
 * volume), physical units. */
double
EnclosedVolume(const MeshType * mesh)
{
  double volume = 0.0;
  for (auto cell = mesh->GetCells()->Begin(); cell != mesh->GetCells()->End(); ++cell)
  {
    const auto * c = cell.Value();
    if (c->GetNumberOfPoints() != 3)
    {
      continue;
    }
    const auto * ids = c->GetPointIds();
    const auto & a = mesh->GetPoint(ids[0]);
    const auto & b = mesh->GetPoint(ids[1]);
    const auto & d = mesh->GetPoint(ids[2]);
    volume +=
      a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) + a[2] * (b[0] * d[1] - b[1] * d[0]);
  }
  return std::abs(volume) / 6.0;
}

/** The final mesh's quality for the summary: intersecting pairs of
 * triangles sharing no vertex, the smallest angle of its triangles, and its
 * edge lengths. */
std::string
DescribeQuality(const MeshType * mesh)
{
  double smallestAngle = 180.0;
  double shortest = std::numeric_limits<double>::infinity();
  double longest = 0.0;
  double sum = 0.0;
  size_t edges = 0;
  for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
  {
    const auto * cell = it.Value();
    if (cell->GetNumberOfPoints() != 3)
    {
      continue;
    }
    const auto * ids = cell->GetPointIds();
    for (unsigned int k = 0; k < 3; ++k)
    {
      const auto   a = mesh->GetPoint(ids[k]);
      const auto   b = mesh->GetPoint(ids[(k + 1) % 3]);
      const auto   c = mesh->GetPoint(ids[(k + 2) % 3]);
      const auto   u = b - a;
      const auto   v = c - a;
      const double length = u.GetNorm();
      shortest = std::min(shortest, length);
      longest = std::max(longest, length);
      sum += length;
      ++edges;
      const double denominator = u.GetNorm() * v.GetNorm();
      if (denominator > 0.0)
      {
        const double cosine = std::max(-1.0, std::min(1.0, (u * v) / denominator));
        smallestAngle = std::min(smallestAngle, std::acos(cosine) * 180.0 / 3.141592653589793);
      }
    }
  }
  if (edges == 0)
  {
    return "no triangles";
  }
  const auto intersections = itk::SurfaceCollision::CountSelfIntersections(mesh);
  return std::to_string(intersections) + " intersecting pairs of triangles, smallest angle " +
         Format(smallestAngle, 3) + " degrees, edge length " + Format(shortest, 3) + " to " + Format(longest, 3) +
         " mm (mean " + Format(sum / static_cast<double>(edges), 3) + " mm; interior edges counted twice)";
}

/** A surface that left the image or collapsed is a failed run (exit 1),
 * not a result: nothing is written. An object cut by the image's edge (the
 * brainstem at the bottom of a head scan) holds the surface at that edge,
 * where a vertex outside the image deflates: points within one voxel beyond
 * the edge are that, not a surface that left. */
void
CheckFinalSurface(const ImageType * image, const MeshType * initial, const MeshType * final)
{
  size_t outside = 0;
  for (auto it = final->GetPoints()->Begin(); it != final->GetPoints()->End(); ++it)
  {
    outside += IsInsideImage(image, it.Value(), 1.0) ? 0 : 1;
  }
  if (outside > 0)
  {
    throw Error("the surface left the image: " + std::to_string(outside) + " of " +
                  std::to_string(final->GetNumberOfPoints()) +
                  " points lie more than a voxel outside it (a balloon or region force too strong for the image's "
                  "edges?); nothing "
                  "written",
                ExitFailure);
  }
  const double before = EnclosedVolume(initial);
  const double after = EnclosedVolume(final);
  if (before > 0.0 && after < 1e-3 * before)
  {
    throw Error("the surface collapsed: it encloses " + Format(after) + " mm^3, " + Format(100.0 * after / before) +
                  " % of the initial " + Format(before) + " mm^3; nothing written",
                ExitFailure);
  }
}

struct DeformResult
{
  MeshType::Pointer       mesh;
  ForceImageType::Pointer force;
  double                  sigma{ 0.0 };
  double                  scale{ 0.0 };
  itk::SizeValueType      iterations{ 0 };
  bool                    converged{ false };
  double                  lastMaximumDisplacement{ 0.0 };
};

/** Called with the mesh of every K-th iteration (and of the first and last). */
using SnapshotCallback = std::function<void(const MeshType *, itk::SizeValueType)>;

/** The force field and the deformation, by the ITK filters. */
DeformResult
Deform(const ImageType *        image,
       const MeshType *         initial,
       const SegmentOptions &   o,
       Progress &               progress,
       const SnapshotCallback & snapshot = SnapshotCallback())
{
  DeformResult result;
  result.sigma = ForceSigma(image, o);
  result.scale = ForceScale(image, o);
  result.force = ComputeForceField<ForceFilterType>(image, o, progress);

  // Coarse to fine: the surface first converges at the resolution it is
  // given (the coarse default sphere, whose long edges bridge pockets such as
  // ventricles and sulci that would trap a fine mesh), on an image smoothed
  // twice as much for the region force; it is then subdivided (each triangle
  // into four) and deformed again, until its mean edge length reaches
  // --edge-length. The object's intensity range is estimated once, from the
  // initial surface.
  const double  smallest = SmallestSpacing(image);
  LevelSchedule schedule;
  schedule.scale = result.scale;
  schedule.regionWeight = o.regionWeight >= 0.0 ? o.regionWeight : defaults::RegionWeightInVoxels * smallest;
  schedule.regionSigma = o.regionSigma >= 0.0 ? o.regionSigma : defaults::RegionSigmaInVoxels * smallest;
  schedule.edgeSearchWeight =
    o.edgeSearchWeight >= 0.0 ? o.edgeSearchWeight : defaults::EdgeSearchWeightInVoxels * smallest;
  schedule.edgeSearchDistance =
    o.edgeSearchDistance > 0.0 ? o.edgeSearchDistance : defaults::EdgeSearchDistanceInVoxels * smallest;
  schedule.edgeLength = o.edgeLength > 0.0 ? o.edgeLength : defaults::EdgeLengthInVoxels * smallest;
  schedule.tangentialElasticity = o.tangentialElasticity;
  schedule.pointsWord = "vertices";
  schedule.initialWhat = "surface";
  MeshType::ConstPointer stageInput = initial;
  LevelState             state;
  if (snapshot)
  {
    snapshot(initial, 0);
  }
  // One filter for all levels: its smoothed intensity image and statistics
  // are kept from one level to the next when the region sigma is the same.
  auto deform = DeformFilterType::New();
  for (unsigned int stage = 0;; ++stage)
  {
    // The last level: refinement off (no region force), a mesh with cells
    // other than triangles (not refined), or a first level already fine
    // enough (later levels are decided on their output below).
    bool last = schedule.regionWeight == 0.0 || !HasOnlyTriangles(stageInput) ||
                !(MeanEdgeLength(stageInput) > 1.5 * schedule.edgeLength);
    deform->SetInput(stageInput);
    deform->SetForceImage(result.force);
    deform->SetIntensityImage(image);
    ConfigureLevel(deform.GetPointer(), o, schedule, state, stage, last, MeanEdgeLength(stageInput));
    deform->SetPreventSelfIntersections(o.preventSelfIntersections);
    deform->SetMinimumDistance(
      o.minimumDistance >= 0.0 ? o.minimumDistance : defaults::MinimumDistanceOverEdgeLength * schedule.edgeLength);
    RunLevel(deform.GetPointer(),
             o,
             schedule,
             progress,
             stageInput->GetNumberOfPoints(),
             state,
             snapshot ? std::function<void(itk::SizeValueType)>(
                          [&](itk::SizeValueType iteration) { snapshot(deform->GetOutput(), iteration); })
                      : std::function<void(itk::SizeValueType)>());
    result.iterations = state.iterations;
    result.converged = state.converged;
    result.lastMaximumDisplacement = state.lastMaximumDisplacement;
    MeshType::Pointer output = deform->GetOutput();
    output->DisconnectPipeline();
    last = last || !(MeanEdgeLength(output) > 1.5 * schedule.edgeLength) ||
           4 * output->GetNumberOfPoints() > defaults::MaximumRefinedPoints;
    if (last)
    {
      result.mesh = output;
      break;
    }
    stageInput = SubdivideTriangles(output);
  }
  return result;
}

} // namespace

void
SetNumberOfThreads(unsigned int threads)
{
  if (threads > 0)
  {
    itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(threads);
  }
}

const CoreDefaults &
GetCoreDefaults()
{
  // Read once from default-constructed filters: the core is the single source
  // of truth for these defaults.
  static const CoreDefaults defaults = []() {
    const auto   force = ForceFilterType::New();
    const auto   deform = DeformFilterType::New();
    CoreDefaults d;
    d.NormalizeForces = force->GetNormalizeForces();
    d.GradientVectorFlow = force->GetUseGradientVectorFlow();
    d.GradientVectorFlowRegularization = force->GetGradientVectorFlowRegularization();
    d.GradientVectorFlowIterations = force->GetGradientVectorFlowIterations();
    d.TangentialElasticity = deform->GetTangentialElasticity();
    d.Balloon = deform->GetBalloon();
    d.MaximumStepLength = deform->GetMaximumStepLength();
    d.ConvergenceWindow = deform->GetConvergenceWindow();
    d.IntensityTolerance = deform->GetIntensityTolerance();
    return d;
  }();
  return defaults;
}

bool
HasVTK()
{
#ifdef EDM_HAVE_VTK
  return true;
#else
  return false;
#endif
}

std::string
GetLibraryVersions()
{
  return "ITK " + std::string(itk::Version::GetITKVersion()) + (HasVTK() ? ", with VTK" : ", without VTK");
}

int
RunSegment(const SegmentOptions & o, const GlobalOptions & global)
{
  namespace fs = std::filesystem;
  // Every output is checked before the long computation starts.
  CheckMeshOutputPath(o.output, "--output");
  if (!o.forceOutput.empty())
  {
    CheckImageOutputPath(o.forceOutput, "--force-output");
  }
  if (!o.snapshots.empty())
  {
    if (!HasVTK())
    {
      throw Error("--snapshots: the .pvd time series needs VTK, and this edmodel was built without VTK");
    }
    const fs::path  directory(o.snapshots);
    std::error_code error;
    if (fs::exists(directory, error) && !fs::is_directory(directory, error))
    {
      throw Error("--snapshots: '" + o.snapshots + "' is not a directory");
    }
    const fs::path parent = directory.has_parent_path() ? directory.parent_path() : fs::path(".");
    if (!fs::is_directory(parent, error))
    {
      throw Error("--snapshots: directory '" + parent.string() + "' does not exist");
    }
  }

  Progress           progress(global.quiet);
  ImageType::Pointer image = ReadImage(o.image, o.gradientVectorFlow);
  MeshType::Pointer  initial;
  if (!o.initMesh.empty())
  {
    initial = ReadMesh(o.initMesh, "--init-mesh");
    CheckInitialMesh(image, initial, o.initMesh, progress);
    if (o.preventSelfIntersections)
    {
      const auto intersections = itk::SurfaceCollision::CountSelfIntersections(initial.GetPointer());
      if (intersections > 0)
      {
        throw Error("--init-mesh: mesh '" + o.initMesh + "' intersects itself (" + std::to_string(intersections) +
                    " pairs of triangles sharing no vertex intersect), and the collision test "
                    "(--prevent-self-intersections, on by default) needs a surface that does not; repair it, or pass "
                    "--allow-self-intersections");
      }
    }
  }
  else
  {
    initial = MakeInitialSphere(image, o);
  }
  const auto size = image->GetLargestPossibleRegion().GetSize();
  progress.Note("image " + std::to_string(size[0]) + " x " + std::to_string(size[1]) + " x " + std::to_string(size[2]) +
                ", spacing " + Format(image->GetSpacing()[0]) + " x " + Format(image->GetSpacing()[1]) + " x " +
                Format(image->GetSpacing()[2]) + " mm; initial mesh " + std::to_string(initial->GetNumberOfPoints()) +
                " points");

  std::unique_ptr<SnapshotSeries> series;
  SnapshotCallback                snapshot;
#ifdef EDM_HAVE_VTK
  if (!o.snapshots.empty())
  {
    // The series is named after the output mesh: out/liver.vtk -> DIR/liver.pvd.
    series = std::make_unique<SnapshotSeries>(o.snapshots, fs::path(o.output).stem().string());
    snapshot = [&series](const MeshType * mesh, itk::SizeValueType iteration) { series->Add(mesh, iteration); };
  }
#endif

  const DeformResult result = RunRepeated(o, progress, [&](Progress & runProgress, bool first) {
    return Deform(image, initial, o, runProgress, first ? snapshot : SnapshotCallback());
  });
  CheckFinalSurface(image, initial, result.mesh);

  if (!o.forceOutput.empty())
  {
    WriteImage(result.force, o.forceOutput);
  }
  WriteMesh(result.mesh, o.output);
  if (series)
  {
    series->Commit();
    progress.Note("wrote " + std::to_string(series->GetNumberOfFiles()) + " snapshots, every " +
                  std::to_string(o.snapshotEvery) + " iterations: " + series->GetCollectionPath());
  }
  if (!global.quiet)
  {
    std::cout << "edmodel: wrote " << o.output << " (" << result.mesh->GetNumberOfPoints() << " points, "
              << CountSurfaceCells(result.mesh) << " faces) after " << result.iterations << " iterations"
              << (result.converged ? ", converged" : ", not converged") << std::endl;
    std::cout << "edmodel: surface quality: " << DescribeQuality(result.mesh) << std::endl;
  }
  return ExitSuccess;
}

int
RunDemo(const DemoOptions & options, const GlobalOptions & global)
{
  namespace fs = std::filesystem;
  std::error_code error;
  fs::create_directories(options.outputDirectory, error);
  if (!fs::is_directory(options.outputDirectory))
  {
    throw Error("--output-dir: cannot create directory '" + options.outputDirectory + "'" +
                (error ? ": " + error.message() : std::string()));
  }
  const fs::path directory(options.outputDirectory);
  const auto     imagePath = (directory / "demo-image.nii.gz").string();
  const auto     forcePath = (directory / "demo-force.mha").string();
  const auto     spherePath = (directory / "demo-sphere.vtk").string();
  const auto     meshPath = (directory / "demo-mesh.vtk").string();
  const auto     figurePath = (directory / "demo-figure1.png").string();

  // The seed's example: a 64^3 binary ellipsoid and a sphere at its centre.
  const double                      centerValues[3] = { 31.0, 31.0, 31.0 };
  const double                      radiiValues[3] = { 18.0, 14.0, 28.0 };
  constexpr double                  sphereRadius = 16.0;
  itk::EllipsoidPhantom::PointType  center(centerValues);
  itk::EllipsoidPhantom::VectorType radii(radiiValues);
  const itk::EllipsoidPhantom       phantom(center, radii);

  ImageType::SizeType size;
  size.Fill(64);
  ImageType::SpacingType   spacing(1.0);
  ImageType::PointType     origin(0.0);
  ImageType::DirectionType direction;
  direction.SetIdentity();
  ImageType::Pointer image = phantom.MakeImage<ImageType>(size, spacing, origin, direction, 1.0f, 0.0f);

  SegmentOptions segment; // the defaults of 'edmodel segment'
  segment.gradientVectorFlow = defaults::DemoGradientVectorFlow;
  segment.hasInitSphere = true;
  for (unsigned int k = 0; k < 3; ++k)
  {
    segment.sphere[k] = centerValues[k];
  }
  segment.sphere[3] = sphereRadius;
  MeshType::Pointer sphere = MakeInitialSphere(image, segment);

  Progress progress(global.quiet);
  progress.Note("demo: 64^3 binary ellipsoid of radii (18, 14, 28) voxels centred at (31, 31, 31); sphere of radius " +
                Format(sphereRadius) + " at the centre, " + std::to_string(sphere->GetNumberOfPoints()) + " points");
  std::unique_ptr<SnapshotSeries> series;
#ifdef EDM_HAVE_VTK
  series = std::make_unique<SnapshotSeries>((directory / "series").string(), "demo");
#endif
  // Figure 1 (with VTK rendering and a display, or a VTK that needs none).
  const std::string          noFigure = FigureOne::WhyUnavailable();
  std::unique_ptr<FigureOne> figure;
  if (noFigure.empty())
  {
    figure = std::make_unique<FigureOne>();
  }
  SnapshotCallback snapshot;
  if (series || figure)
  {
    segment.snapshotEvery = 10; // Figure 1 shows iterations 10 and 50.
    snapshot = [&series, &figure](const MeshType * mesh, itk::SizeValueType iteration) {
      if (series)
      {
        series->Add(mesh, iteration);
      }
      if (figure)
      {
        figure->Add(mesh, iteration);
      }
    };
  }
  const DeformResult result = Deform(image, sphere, segment, progress, snapshot);

  WriteImage(image, imagePath);
  WriteImage(result.force, forcePath);
  WriteMesh(sphere, spherePath);
  WriteMesh(result.mesh, meshPath);
  std::string written = imagePath + ", " + forcePath + ", " + spherePath + ", " + meshPath;
  if (series)
  {
    series->Commit();
    written += ", " + series->GetCollectionPath() + " (" + std::to_string(series->GetNumberOfFiles()) +
               " snapshots, open it in ParaView)";
  }
  if (figure)
  {
    figure->Write(image, result.mesh, result.iterations, figurePath);
    written += ", " + figurePath + " (Figure 1)";
  }

  double mean = 0.0;
  double maximum = 0.0;
  phantom.MeasureDistance(result.mesh.GetPointer(), mean, maximum);
  double initialMean = 0.0;
  double initialMaximum = 0.0;
  phantom.MeasureDistance(sphere.GetPointer(), initialMean, initialMaximum);
  const bool good = mean < defaults::DemoMeanDistanceLimit && maximum < defaults::DemoMaximumDistanceLimit;

  // The result goes to stdout even with --quiet: it is what the demo is for.
  std::cout << "edmodel demo: sphere -> ellipsoid in " << result.iterations << " iterations"
            << (result.converged ? " (converged)" : " (iteration cap)") << "\n"
            << "  distance to the true ellipsoid, initial sphere: mean " << Format(initialMean) << " voxel, max "
            << Format(initialMaximum) << " voxel\n"
            << "  distance to the true ellipsoid, final mesh:     mean " << Format(mean) << " voxel, max "
            << Format(maximum) << " voxel\n"
            << "  accuracy " << (good ? "good" : "POOR") << " (limits: mean < " << defaults::DemoMeanDistanceLimit
            << " voxel, max < " << defaults::DemoMaximumDistanceLimit << " voxel)\n"
            << "  wrote " << written << "\n"
            << (figure ? std::string() : "  skipped " + figurePath + " (Figure 1): " + noFigure + "\n")
            << "  same run by hand: edmodel segment --image " << imagePath << " --init-sphere 31,31,31,16"
            << (segment.gradientVectorFlow ? " --gvf" : "") << " --output " << (directory / "mesh.vtk").string()
            << "\n";
  return good ? ExitSuccess : ExitFailure;
}

} // namespace edm
