
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

#include <algorithm>
#include <cctype>
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
    // To memory, then to the file with every write checked: VTK's XML writer
    // crashes on a full disk.
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetInputData(polyData);
    writer->WriteToOutputStringOn();
    writer->SetDataModeToBinary(); // inline: ParaView 5.11 on Debian 12 cannot parse appended data
    writer->SetCompressorTypeToZLib();
    written = writer->Write();
    if (written == 1)
    {
      WriteFileContents(writer->GetOutputString(), path);
    }
  }
  if (written != 1)
  {
    throw Error("cannot write mesh '" + path + "'");
  }
}

struct SnapshotSeries::Internals
{
  std::string                               directory;
  std::string                               name;
  std::string                               collection;
  bool                                      createdDirectory{ false };
  int                                       cleanup{ -1 };
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
    // Removed if a signal ends the run (only when empty: after the series'
    // temporary directory).
    m_Internals->cleanup = RegisterTemporaryDirectory(directory, false);
  }
  m_Internals->directory = directory;
  m_Internals->name = name;
  m_Internals->collection = (fs::path(directory) / (name + ".pvd")).string();
  m_Internals->output = std::make_unique<AtomicOutput>(m_Internals->collection);
  m_Internals->writer = vtkSmartPointer<vtkIterationSeriesWriter>::New();
  m_Internals->writer->SetFileName(m_Internals->output->GetTemporaryPath().c_str());
}

SnapshotSeries::~SnapshotSeries()
{
  const bool createdDirectory = m_Internals->createdDirectory;
  const auto directory = m_Internals->directory;
  UnregisterTemporaryDirectory(m_Internals->cleanup);
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
  // A signal that ends the run while the file is written removes the
  // series' temporary directory after it, not during it.
  const auto lock = LockTemporaryOutputs();
  if (m_Internals->writer->WriteIteration(polyData, static_cast<int>(iteration)) != 1)
  {
    throw Error("--snapshots: cannot write the mesh of iteration " + std::to_string(iteration) + " in '" +
                m_Internals->directory + "' (is the disk full?)");
  }
}

void
SnapshotSeries::Commit()
{
  if (m_Internals->writer->WriteCollection() != 1)
  {
    throw Error("--snapshots: cannot write '" + m_Internals->collection + "' (is the disk full?)");
  }
  // The files of an earlier series of this name that the new one does not
  // replace would mix with it: removed first.
  std::error_code   error;
  const fs::path    temporary = fs::path(m_Internals->output->GetTemporaryPath()).parent_path();
  const std::string prefix = m_Internals->name + "_";
  for (const auto & entry : fs::directory_iterator(m_Internals->directory, error))
  {
    const std::string file = entry.path().filename().string();
    const bool        numbered = file.size() > prefix.size() + 4 && file.compare(0, prefix.size(), prefix) == 0 &&
                          file.compare(file.size() - 4, 4, ".vtp") == 0 &&
                          std::all_of(file.begin() + static_cast<std::ptrdiff_t>(prefix.size()),
                                      file.end() - 4,
                                      [](unsigned char c) { return std::isdigit(c) != 0; });
    if (numbered && !fs::exists(temporary / file))
    {
      std::error_code ignored;
      fs::remove(entry.path(), ignored);
    }
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
