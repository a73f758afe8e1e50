
// The seed's Figure 1 for edmodel demo, rendered by the code the rendering
// examples use (vtk/rendering). Compiled only when VTK rendering is built.

#include "edmodelIO.h"
#include "edmodelOptions.h"

#include "edmMeshBridge.h"
#include "edmRendering.h"
#include "vtkImageData.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"

#include <utility>
#include <vector>

namespace edm
{

namespace
{
/** The iterations Figure 1 shows, besides the last. */
constexpr itk::SizeValueType FigureIterations[] = { 0, 10, 50 };

vtkSmartPointer<vtkPolyData>
ToPolyData(const MeshType * mesh)
{
  edm::MeshBridgeOptions options;
  options.PointData = false;
  options.CellData = false;
  return edm::MeshToPolyData(mesh, options);
}
} // namespace

struct FigureOne::Internals
{
  std::vector<std::pair<itk::SizeValueType, vtkSmartPointer<vtkPolyData>>> meshes;
};

FigureOne::FigureOne()
  : m_Internals(new Internals)
{}

FigureOne::~FigureOne()
{
  delete m_Internals;
}

std::string
FigureOne::WhyUnavailable()
{
  return edm::WhyNoOffscreenRendering();
}

void
FigureOne::Add(const MeshType * mesh, itk::SizeValueType iteration)
{
  for (const auto shown : FigureIterations)
  {
    if (iteration == shown)
    {
      m_Internals->meshes.emplace_back(iteration, ToPolyData(mesh)); // a copy
    }
  }
}

void
FigureOne::Write(const ImageType *   image,
                 const MeshType *    last,
                 itk::SizeValueType  lastIteration,
                 const std::string & path)
{
  vtkObject::GlobalWarningDisplayOff();
  // The kept meshes before the last iteration (a run that stops before
  // iteration 50 shows fewer views), then the last.
  const vtkSmartPointer<vtkPolyData> lastMesh = ToPolyData(last);
  std::vector<vtkPolyData *>         meshes;
  std::vector<int>                   iterations;
  for (const auto & kept : m_Internals->meshes)
  {
    if (kept.first < lastIteration)
    {
      meshes.push_back(kept.second);
      iterations.push_back(static_cast<int>(kept.first));
    }
  }
  meshes.push_back(lastMesh);
  iterations.push_back(static_cast<int>(lastIteration));

  auto         intensity = edm::ImageToImageData(image, "Intensity");
  AtomicOutput output(path);
  std::string  error;
  if (!edm::WriteFigurePNG(intensity, meshes, iterations, output.GetTemporaryPath(), error))
  {
    throw Error("cannot write '" + path + "': " + error);
  }
  output.Commit();
}

} // namespace edm
