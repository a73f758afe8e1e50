
// The formats that need VTK: .vtp and .stl meshes, and the .pvd time series
// of --snapshots. Compiled only when the VTK module of this project is built.

#include "edmodelIO.h"
#include "edmodelOptions.h"

#include "edmMeshBridge.h"
#include "vtkIterationSeriesWriter.h"
#include "vtkNew.h"
#include "vtkSTLReader.h"
#include "vtkSTLWriter.h"
#include "vtkXMLPolyDataReader.h"
#include "vtkXMLPolyDataWriter.h"

#include <filesystem>
#include <memory>

namespace fs = std::filesystem;

namespace edm
{

MeshType::Pointer
ReadPolyDataMesh(const std::string & path)
{
  // Errors are reported by edmodel in one line, not by VTK's output window.
  vtkObject::GlobalWarningDisplayOff();
  vtkSmartPointer<vtkPolyData> polyData;
  if (GetExtension(path) == ".stl")
  {
    vtkNew<vtkSTLReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    polyData = reader->GetOutput();
  }
  else
  {
    vtkNew<vtkXMLPolyDataReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    if (reader->GetErrorCode() != 0)
    {
      throw Error("cannot read mesh '" + path + "': not a VTK XML polydata file");
    }
    polyData = reader->GetOutput();
  }
  if (polyData == nullptr || polyData->GetNumberOfPoints() == 0)
  {
    throw Error("cannot read mesh '" + path + "': no points");
  }
  edm::MeshBridgeOptions options;
  options.PointData = false;
  options.CellData = false;
  return edm::PolyDataToMesh<MeshType>(polyData, options);
}

void
WritePolyDataMesh(const MeshType * mesh, const std::string & path)
{
  vtkObject::GlobalWarningDisplayOff();
  edm::MeshBridgeOptions options;
  options.PointData = false;
  options.CellData = false;
  vtkSmartPointer<vtkPolyData> polyData = edm::MeshToPolyData(mesh, options);
  int                          written = 0;
  if (GetExtension(path) == ".stl")
  {
    vtkNew<vtkSTLWriter> writer;
    writer->SetInputData(polyData);
    writer->SetFileName(path.c_str());
    writer->SetFileTypeToBinary();
    written = writer->Write();
  }
  else
  {
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetInputData(polyData);
    writer->SetFileName(path.c_str());
    writer->SetDataModeToBinary(); // inline: ParaView 5.11 on Debian 12 cannot parse appended data
    writer->SetCompressorTypeToZLib();
    written = writer->Write();
  }
  if (written != 1)
  {
    throw Error("cannot write mesh '" + path + "'");
  }
}

struct SnapshotSeries::Internals
{
  std::string                               directory;
  std::string                               collection;
  bool                                      createdDirectory{ false };
  std::unique_ptr<AtomicOutput>             output;
  vtkSmartPointer<vtkIterationSeriesWriter> writer;
};

SnapshotSeries::SnapshotSeries(const std::string & directory, const std::string & name)
  : m_Internals(new Internals)
{
  vtkObject::GlobalWarningDisplayOff();
  std::error_code error;
  if (fs::exists(directory, error) && !fs::is_directory(directory, error))
  {
    throw Error("--snapshots: '" + directory + "' is not a directory");
  }
  if (!fs::exists(directory, error))
  {
    const fs::path parent = fs::path(directory).has_parent_path() ? fs::path(directory).parent_path() : ".";
    if (!fs::is_directory(parent, error))
    {
      throw Error("--snapshots: directory '" + parent.string() + "' does not exist");
    }
    if (!fs::create_directory(directory, error))
    {
      throw Error("--snapshots: cannot create directory '" + directory + "': " + error.message());
    }
    m_Internals->createdDirectory = true;
  }
  m_Internals->directory = directory;
  m_Internals->collection = (fs::path(directory) / (name + ".pvd")).string();
  m_Internals->output = std::make_unique<AtomicOutput>(m_Internals->collection);
  m_Internals->writer = vtkSmartPointer<vtkIterationSeriesWriter>::New();
  m_Internals->writer->SetFileName(m_Internals->output->GetTemporaryPath().c_str());
}

SnapshotSeries::~SnapshotSeries()
{
  const bool createdDirectory = m_Internals->createdDirectory;
  const auto directory = m_Internals->directory;
  delete m_Internals;
  if (createdDirectory)
  {
    // Removes the directory made for the series when nothing was committed.
    std::error_code error;
    fs::remove(directory, error);
  }
}

void
SnapshotSeries::Add(const MeshType * mesh, itk::SizeValueType iteration)
{
  edm::MeshBridgeOptions options;
  options.PointData = false;
  options.CellData = false;
  vtkSmartPointer<vtkPolyData> polyData = edm::MeshToPolyData(mesh, options);
  if (m_Internals->writer->WriteIteration(polyData, static_cast<int>(iteration)) != 1)
  {
    throw Error("--snapshots: cannot write the mesh of iteration " + std::to_string(iteration) + " in '" +
                m_Internals->directory + "'");
  }
}

void
SnapshotSeries::Commit()
{
  if (m_Internals->writer->WriteCollection() != 1)
  {
    throw Error("--snapshots: cannot write '" + m_Internals->collection + "'");
  }
  m_Internals->output->Commit();
  m_Internals->createdDirectory = false;
}

std::string
SnapshotSeries::GetCollectionPath() const
{
  return m_Internals->collection;
}

unsigned int
SnapshotSeries::GetNumberOfFiles() const
{
  return static_cast<unsigned int>(m_Internals->writer->GetNumberOfWrittenFiles());
}

} // namespace edm
