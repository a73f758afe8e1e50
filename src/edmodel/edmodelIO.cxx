
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

const char * const MeshExtensions = ".vtk, .obj, .off or .gii";

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

/** The path of the temporary directory of the write in progress, for the
 * signal handler: an interrupted run leaves nothing behind. */
char g_PendingFile[4096] = { 0 };
char g_PendingDirectory[4096] = { 0 };

extern "C" void
RemovePendingOutput(int signalNumber)
{
  if (g_PendingFile[0] != '\0')
  {
    unlink(g_PendingFile);
  }
  if (g_PendingDirectory[0] != '\0')
  {
    rmdir(g_PendingDirectory);
  }
  std::signal(signalNumber, SIG_DFL);
  std::raise(signalNumber);
}

/** Writes go to DIR/.edmodel-PID-NAME/NAME (same file system, same file name so
 * that ITK picks the same format and multi-file formats such as .mhd + .raw
 * keep consistent names), then every file is renamed into DIR. */
class AtomicOutput
{
public:
  explicit AtomicOutput(const std::string & path)
    : m_Final(path)
  {
    const fs::path finalPath(path);
    const fs::path directory = finalPath.has_parent_path() ? finalPath.parent_path() : fs::path(".");
    m_Directory = directory / (".edmodel-" + std::to_string(getpid()) + "-" + finalPath.filename().string());
    std::error_code error;
    fs::remove_all(m_Directory, error);
    if (!fs::create_directory(m_Directory, error))
    {
      throw Error("cannot write " + Quote(path) + ": " + error.message());
    }
    m_Temporary = m_Directory / finalPath.filename();
    std::strncpy(g_PendingDirectory, m_Directory.c_str(), sizeof(g_PendingDirectory) - 1);
    std::strncpy(g_PendingFile, m_Temporary.c_str(), sizeof(g_PendingFile) - 1);
    std::signal(SIGINT, RemovePendingOutput);
    std::signal(SIGTERM, RemovePendingOutput);
  }

  ~AtomicOutput()
  {
    std::error_code error;
    fs::remove_all(m_Directory, error);
    g_PendingFile[0] = '\0';
    g_PendingDirectory[0] = '\0';
  }

  std::string
  GetTemporaryPath() const
  {
    return m_Temporary.string();
  }

  void
  Commit()
  {
    const fs::path  destination = fs::path(m_Final).has_parent_path() ? fs::path(m_Final).parent_path() : ".";
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

  AtomicOutput(const AtomicOutput &) = delete;
  AtomicOutput &
  operator=(const AtomicOutput &) = delete;

private:
  std::string m_Final;
  fs::path    m_Directory;
  fs::path    m_Temporary;
};

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
  while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back())))
  {
    line.pop_back();
  }
  return line.empty() ? std::string("unknown error") : line;
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

MeshType::Pointer
ReadMesh(const std::string & path, const std::string & option)
{
  CheckReadableFile(path, "mesh");
  itk::MeshIOBase::Pointer io = itk::MeshIOFactory::CreateMeshIO(path.c_str(), itk::IOFileModeEnum::ReadMode);
  if (io.IsNull())
  {
    throw Error(option + ": cannot read mesh " + Quote(path) + ": unknown mesh format (use " + MeshExtensions + ")");
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

void
CheckMeshOutputPath(const std::string & path, const std::string & option)
{
  const std::string extension = GetExtension(path);
  if (NeedsVTK(extension) && !HasVTK())
  {
    throw Error(option + ": writing " + extension + " needs VTK, and this edmodel was built without VTK (use " +
                MeshExtensions + ")");
  }
  if (!IsWritableMeshExtension(extension))
  {
    throw Error(option + ": unknown mesh extension '" + extension + "' in " + Quote(path) + " (use " + MeshExtensions +
                ")");
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
  auto         writer = itk::MeshFileWriter<MeshType>::New();
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
