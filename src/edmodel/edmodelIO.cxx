
#include "edmodelIO.h"
#include "edmodelOptions.h"

#include "itkGDCMImageIO.h"
#include "itkGDCMSeriesFileNames.h"
#include "itkImageFileReader.h"
#include "itkImageFileWriter.h"
#include "itkImageIOFactory.h"
#include "itkImageSeriesReader.h"
#include "itkMeshFileReader.h"
#include "itkMeshFileWriter.h"
#include "itkMeshIOFactory.h"

#include <algorithm>
#include <cctype>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace fs = std::filesystem;

namespace edm
{
namespace
{

const char *
MeshExtensionsText()
{
  return HasVTK() ? ".vtk, .obj, .off, .gii, .vtp or .stl" : ".vtk, .obj, .off or .gii";
}

bool
IsWritableMeshExtension(const std::string & extension)
{
  return extension == ".vtk" || extension == ".obj" || extension == ".off" || extension == ".gii";
}

bool
NeedsVTK(const std::string & extension)
{
  return extension == ".vtp" || extension == ".stl" || extension == ".pvd";
}

std::string
Quote(const std::string & path)
{
  return "'" + path + "'";
}

/** The temporary outputs in progress, for the signal handler: an interrupted
 * run leaves nothing behind (the handler can only unlink a file and remove an
 * empty directory: async-signal-safe calls). */
struct PendingOutput
{
  char file[4096];
  char directory[4096];
};
constexpr int MaximumPendingOutputs = 4;
PendingOutput g_Pending[MaximumPendingOutputs] = {};

extern "C" void
RemovePendingOutputs(int signalNumber)
{
  for (auto & pending : g_Pending)
  {
    if (pending.file[0] != '\0')
    {
      unlink(pending.file);
    }
    if (pending.directory[0] != '\0')
    {
      rmdir(pending.directory);
    }
  }
  std::signal(signalNumber, SIG_DFL);
  std::raise(signalNumber);
}

int
RegisterPendingOutput(const std::string & file, const std::string & directory)
{
  for (int slot = 0; slot < MaximumPendingOutputs; ++slot)
  {
    auto & pending = g_Pending[slot];
    if (pending.directory[0] == '\0' && file.size() < sizeof(pending.file) &&
        directory.size() < sizeof(pending.directory))
    {
      std::copy(file.begin(), file.end(), pending.file);
      pending.file[file.size()] = '\0';
      std::copy(directory.begin(), directory.end(), pending.directory);
      pending.directory[directory.size()] = '\0';
      std::signal(SIGINT, RemovePendingOutputs);
      std::signal(SIGTERM, RemovePendingOutputs);
      return slot;
    }
  }
  return -1;
}

void
UnregisterPendingOutput(int slot)
{
  if (slot >= 0)
  {
    g_Pending[slot].directory[0] = '\0';
    g_Pending[slot].file[0] = '\0';
  }
}

void
CheckOutputDirectory(const std::string & path, const std::string & option)
{
  const fs::path  p(path);
  const fs::path  directory = p.has_parent_path() ? p.parent_path() : fs::path(".");
  std::error_code error;
  if (!fs::is_directory(directory, error))
  {
    throw Error(option + ": directory " + Quote(directory.string()) + " does not exist");
  }
  if (fs::is_directory(p, error))
  {
    throw Error(option + ": " + Quote(path) + " is a directory");
  }
  if (access(directory.c_str(), W_OK) != 0)
  {
    throw Error(option + ": directory " + Quote(directory.string()) + " is not writable");
  }
}

void
CheckReadableFile(const std::string & path, const std::string & what)
{
  std::error_code error;
  if (!fs::exists(path, error))
  {
    throw Error("cannot read " + what + " " + Quote(path) + ": no such file or directory");
  }
  std::ifstream stream(path, std::ios::binary);
  if (!stream)
  {
    throw Error("cannot read " + what + " " + Quote(path) + ": " + std::strerror(errno));
  }
}

std::string
DescribeSize(const std::vector<size_t> & size)
{
  std::string text;
  for (size_t i = 0; i < size.size(); ++i)
  {
    text += (i == 0 ? "" : " x ") + std::to_string(size[i]);
  }
  return text;
}

ImageType::Pointer
ReadDicomSeries(const std::string & directory)
{
  auto names = itk::GDCMSeriesFileNames::New();
  names->SetUseSeriesDetails(true);
  names->SetDirectory(directory);
  std::vector<std::string> files;
  try
  {
    // The longest series, when the directory holds several.
    for (const auto & uid : names->GetSeriesUIDs())
    {
      const auto series = names->GetFileNames(uid);
      if (series.size() > files.size())
      {
        files = series;
      }
    }
  }
  catch (const itk::ExceptionObject & exception)
  {
    throw Error("cannot read DICOM directory " + Quote(directory) + ": " + OneLine(exception.GetDescription()));
  }
  if (files.empty())
  {
    throw Error("cannot read image " + Quote(directory) + ": a directory with no DICOM series");
  }
  using ReaderType = itk::ImageSeriesReader<ImageType>;
  auto reader = ReaderType::New();
  reader->SetImageIO(itk::GDCMImageIO::New());
  reader->SetFileNames(files);
  try
  {
    reader->Update();
  }
  catch (const itk::ExceptionObject & exception)
  {
    throw Error("cannot read DICOM series in " + Quote(directory) + ": " + OneLine(exception.GetDescription()));
  }
  ImageType::Pointer image = reader->GetOutput();
  const auto         size = image->GetLargestPossibleRegion().GetSize();
  if (size[2] < 2)
  {
    throw Error("image " + Quote(directory) + " is 2-D (" + DescribeSize({ size[0], size[1] }) +
                ", one DICOM slice): edmodel needs a 3-D volume");
  }
  return image;
}

} // namespace

std::string
OneLine(const std::string & text)
{
  std::string line = text.substr(0, text.find_first_of("\r\n"));
  // "ITK ERROR: MeshFileReader(0x5581...): message" -> "message"
  const std::string prefix = "ITK ERROR: ";
  const auto        object = line.find("): ");
  if (line.compare(0, prefix.size(), prefix) == 0 && object != std::string::npos)
  {
    line = line.substr(object + 3);
  }
  while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back())))
  {
    line.pop_back();
  }
  return line.empty() ? std::string("unknown error") : line;
}

AtomicOutput::AtomicOutput(const std::string & path)
  : m_Final(path)
{
  const fs::path finalPath(path);
  const fs::path directory = finalPath.has_parent_path() ? finalPath.parent_path() : fs::path(".");
  const fs::path temporaryDirectory =
    directory / (".edmodel-" + std::to_string(getpid()) + "-" + finalPath.filename().string());
  std::error_code error;
  fs::remove_all(temporaryDirectory, error);
  if (!fs::create_directory(temporaryDirectory, error))
  {
    throw Error("cannot write " + Quote(path) + ": " + error.message());
  }
  m_Directory = temporaryDirectory.string();
  m_Temporary = (temporaryDirectory / finalPath.filename()).string();
  m_Slot = RegisterPendingOutput(m_Temporary, m_Directory);
}

AtomicOutput::~AtomicOutput()
{
  std::error_code error;
  fs::remove_all(m_Directory, error);
  UnregisterPendingOutput(m_Slot);
}

std::string
AtomicOutput::GetTemporaryPath() const
{
  return m_Temporary;
}

void
AtomicOutput::Commit()
{
  const fs::path  finalPath(m_Final);
  const fs::path  destination = finalPath.has_parent_path() ? finalPath.parent_path() : fs::path(".");
  std::error_code error;
  for (const auto & entry : fs::directory_iterator(m_Directory))
  {
    fs::rename(entry.path(), destination / entry.path().filename(), error);
    if (error)
    {
      throw Error("cannot write " + Quote(m_Final) + ": " + error.message());
    }
  }
}

std::string
GetExtension(const std::string & path)
{
  std::string name = fs::path(path).filename().string();
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
  for (const char * compound : { ".nii.gz", ".vtk.gz" })
  {
    const std::string suffix(compound);
    if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
    {
      return suffix;
    }
  }
  const auto dot = name.rfind('.');
  return dot == std::string::npos || dot == 0 ? std::string() : name.substr(dot);
}

ImageType::Pointer
ReadImage(const std::string & path)
{
  std::error_code error;
  if (fs::is_directory(path, error))
  {
    return ReadDicomSeries(path);
  }
  CheckReadableFile(path, "image");
  itk::ImageIOBase::Pointer io = itk::ImageIOFactory::CreateImageIO(path.c_str(), itk::IOFileModeEnum::ReadMode);
  if (io.IsNull())
  {
    throw Error("cannot read image " + Quote(path) + ": no ITK image reader recognises it (extension '" +
                GetExtension(path) + "')");
  }
  io->SetFileName(path);
  try
  {
    io->ReadImageInformation();
  }
  catch (const itk::ExceptionObject & exception)
  {
    throw Error("cannot read image " + Quote(path) + ": " + OneLine(exception.GetDescription()));
  }
  std::vector<size_t> size;
  unsigned int        extent = 0; // dimensions of more than one voxel
  for (unsigned int d = 0; d < io->GetNumberOfDimensions(); ++d)
  {
    size.push_back(io->GetDimensions(d));
    extent += io->GetDimensions(d) > 1 ? 1 : 0;
  }
  const bool flat = size.size() < 3 || size[0] < 2 || size[1] < 2 || size[2] < 2;
  if (flat && extent <= 2)
  {
    throw Error("image " + Quote(path) + " is 2-D (" + DescribeSize(size) + "): edmodel needs a 3-D volume");
  }
  if (flat || extent > 3)
  {
    throw Error("image " + Quote(path) + " is " + std::to_string(size.size()) + "-D (" + DescribeSize(size) +
                "): edmodel needs a 3-D volume");
  }
  auto reader = itk::ImageFileReader<ImageType>::New();
  reader->SetImageIO(io);
  reader->SetFileName(path);
  try
  {
    reader->Update();
  }
  catch (const itk::ExceptionObject & exception)
  {
    throw Error("cannot read image " + Quote(path) + ": " + OneLine(exception.GetDescription()));
  }
  ImageType::Pointer image = reader->GetOutput();
  image->DisconnectPipeline();
  return image;
}

size_t
CountSurfaceCells(const MeshType * mesh)
{
  size_t count = 0;
  if (mesh->GetCells() == nullptr)
  {
    return 0;
  }
  for (auto it = mesh->GetCells()->Begin(); it != mesh->GetCells()->End(); ++it)
  {
    const auto type = it.Value()->GetType();
    if ((type == itk::CellGeometryEnum::TRIANGLE_CELL || type == itk::CellGeometryEnum::POLYGON_CELL ||
         type == itk::CellGeometryEnum::QUADRILATERAL_CELL) &&
        it.Value()->GetNumberOfPoints() >= 3)
    {
      ++count;
    }
  }
  return count;
}

namespace
{
MeshType::Pointer
CheckSurfaceMesh(MeshType::Pointer mesh, const std::string & path, const std::string & option)
{
  if (mesh->GetNumberOfPoints() == 0)
  {
    throw Error(option + ": mesh " + Quote(path) + " has no points");
  }
  if (CountSurfaceCells(mesh) == 0)
  {
    throw Error(option + ": mesh " + Quote(path) + " has no triangles (a surface mesh is needed)");
  }
  return mesh;
}
} // namespace

MeshType::Pointer
ReadMesh(const std::string & path, const std::string & option)
{
  CheckReadableFile(path, "mesh");
  const std::string extension = GetExtension(path);
  if (extension == ".vtp" || extension == ".stl")
  {
    if (!HasVTK())
    {
      throw Error(option + ": reading " + extension + " needs VTK, and this edmodel was built without VTK (use " +
                  MeshExtensionsText() + ")");
    }
    MeshType::Pointer mesh;
    try
    {
      mesh = ReadPolyDataMesh(path);
    }
    catch (const itk::ExceptionObject & exception)
    {
      throw Error(option + ": cannot read mesh " + Quote(path) + ": " + OneLine(exception.GetDescription()));
    }
    catch (const Error & error)
    {
      throw Error(option + ": " + error.what());
    }
    return CheckSurfaceMesh(mesh, path, option);
  }
  itk::MeshIOBase::Pointer io = itk::MeshIOFactory::CreateMeshIO(path.c_str(), itk::IOFileModeEnum::ReadMode);
  if (io.IsNull())
  {
    throw Error(option + ": cannot read mesh " + Quote(path) + ": unknown mesh format (use " + MeshExtensionsText() +
                ")");
  }
  auto reader = itk::MeshFileReader<MeshType>::New();
  reader->SetMeshIO(io);
  reader->SetFileName(path);
  try
  {
    reader->Update();
  }
  catch (const itk::ExceptionObject & exception)
  {
    throw Error(option + ": cannot read mesh " + Quote(path) + ": " + OneLine(exception.GetDescription()));
  }
  MeshType::Pointer mesh = reader->GetOutput();
  mesh->DisconnectPipeline();
  return CheckSurfaceMesh(mesh, path, option);
}

void
CheckMeshOutputPath(const std::string & path, const std::string & option)
{
  const std::string extension = GetExtension(path);
  if (extension == ".pvd")
  {
    throw Error(option + ": a .pvd file is a time series: write it with --snapshots DIR, and the mesh as " +
                MeshExtensionsText());
  }
  if (NeedsVTK(extension) && !HasVTK())
  {
    throw Error(option + ": writing " + extension + " needs VTK, and this edmodel was built without VTK (use " +
                MeshExtensionsText() + ")");
  }
  if (!IsWritableMeshExtension(extension) && !(NeedsVTK(extension) && HasVTK()))
  {
    throw Error(option + ": unknown mesh extension '" + extension + "' in " + Quote(path) + " (use " +
                MeshExtensionsText() + ")");
  }
  CheckOutputDirectory(path, option);
}

void
CheckImageOutputPath(const std::string & path, const std::string & option)
{
  itk::ImageIOBase::Pointer io = itk::ImageIOFactory::CreateImageIO(path.c_str(), itk::IOFileModeEnum::WriteMode);
  if (io.IsNull())
  {
    throw Error(option + ": unknown image extension '" + GetExtension(path) + "' in " + Quote(path) +
                " (use .nii.gz, .nrrd or .mha)");
  }
  CheckOutputDirectory(path, option);
}

void
WriteMesh(const MeshType * mesh, const std::string & path)
{
  AtomicOutput output(path);
  if (NeedsVTK(GetExtension(path)))
  {
    try
    {
      WritePolyDataMesh(mesh, output.GetTemporaryPath());
    }
    catch (const itk::ExceptionObject & exception)
    {
      throw Error("cannot write mesh " + Quote(path) + ": " + OneLine(exception.GetDescription()));
    }
    output.Commit();
    return;
  }
  auto writer = itk::MeshFileWriter<MeshType>::New();
  writer->SetInput(mesh);
  writer->SetFileName(output.GetTemporaryPath());
  try
  {
    writer->Update();
  }
  catch (const itk::ExceptionObject & exception)
  {
    throw Error("cannot write mesh " + Quote(path) + ": " + OneLine(exception.GetDescription()));
  }
  output.Commit();
}

namespace
{
template <typename TImage>
void
WriteAnyImage(const TImage * image, const std::string & path)
{
  AtomicOutput output(path);
  auto         writer = itk::ImageFileWriter<TImage>::New();
  writer->SetInput(image);
  writer->SetFileName(output.GetTemporaryPath());
  writer->UseCompressionOn();
  try
  {
    writer->Update();
  }
  catch (const itk::ExceptionObject & exception)
  {
    throw Error("cannot write image " + Quote(path) + ": " + OneLine(exception.GetDescription()));
  }
  output.Commit();
}
} // namespace

void
WriteImage(const ImageType * image, const std::string & path)
{
  WriteAnyImage(image, path);
}

void
WriteImage(const ForceImageType * image, const std::string & path)
{
  WriteAnyImage(image, path);
}

} // namespace edm

#ifndef EDM_HAVE_VTK
namespace edm
{
// Without VTK, .vtp and .stl are refused before these are reached.
MeshType::Pointer
ReadPolyDataMesh(const std::string & path)
{
  throw Error("cannot read mesh '" + path + "': this edmodel was built without VTK");
}
void
WritePolyDataMesh(const MeshType *, const std::string & path)
{
  throw Error("cannot write mesh '" + path + "': this edmodel was built without VTK");
}

struct SnapshotSeries::Internals
{};
SnapshotSeries::SnapshotSeries(const std::string &, const std::string &)
  : m_Internals(nullptr)
{
  throw Error("--snapshots: the .pvd time series needs VTK, and this edmodel was built without VTK");
}
SnapshotSeries::~SnapshotSeries() = default;
void
SnapshotSeries::Add(const MeshType *, itk::SizeValueType)
{}
void
SnapshotSeries::Commit()
{}
std::string
SnapshotSeries::GetCollectionPath() const
{
  return std::string();
}
unsigned int
SnapshotSeries::GetNumberOfFiles() const
{
  return 0;
}
} // namespace edm
#endif

#ifndef EDM_HAVE_VTK_RENDERING
namespace edm
{
struct FigureOne::Internals
{};
FigureOne::FigureOne()
  : m_Internals(nullptr)
{}
FigureOne::~FigureOne() = default;
std::string
FigureOne::WhyUnavailable()
{
  return "this edmodel was built without VTK rendering";
}
void
FigureOne::Add(const MeshType *, itk::SizeValueType)
{}
void
FigureOne::Write(const ImageType *, const MeshType *, itk::SizeValueType, const std::string & path)
{
  throw Error("cannot write '" + path + "': " + WhyUnavailable());
}
} // namespace edm
#endif
