
#include "edmodelIO.h"
#include "edmodelOptions.h"

#include "itkGDCMImageIO.h"
#include "itkGDCMSeriesFileNames.h"
#include "itkImageFileReader.h"
#include "itkImageFileWriter.h"
#include "itkImageIOFactory.h"
#include "itkImageSeriesReader.h"
#include "itkLineCell.h"
#include "itkMeshFileReader.h"
#include "itkMeshFileWriter.h"
#include "itkMeshIOFactory.h"
#include "itkPolygonCell.h"
#include "itkTriangleCell.h"
#include "itkVertexCell.h"
#ifdef EDM_HAVE_ZLIB
#  include "itk_zlib.h"
#endif

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>
#include <fcntl.h>
#include <pthread.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
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

/** The image formats that hold the 3-component force field. */
bool
IsWritableImageExtension(const std::string & extension)
{
  return extension == ".mha" || extension == ".mhd" || extension == ".nrrd" || extension == ".nhdr" ||
         extension == ".nii" || extension == ".nii.gz";
}

std::string
Quote(const std::string & path)
{
  return "'" + path + "'";
}

std::string
FormatBytes(double bytes)
{
  std::ostringstream stream;
  stream.precision(3);
  if (bytes >= 1e9)
  {
    stream << bytes / 1e9 << " GB";
  }
  else
  {
    stream << bytes / 1e6 << " MB";
  }
  return stream.str();
}

// --- Signals ---------------------------------------------------------------
//
// SIGINT, SIGTERM, SIGHUP, SIGQUIT and SIGPIPE are blocked in every thread
// and taken by one thread in sigwait(): it removes the temporary outputs with
// ordinary calls (not from a signal handler), under the mutex that Commit()
// holds while it renames, then lets the signal end the process.

std::mutex g_CleanupMutex;
struct CleanupEntry
{
  std::string path;
  bool        recursive;
};
std::map<int, CleanupEntry> g_Cleanup;
int                         g_NextCleanup = 0;
sigset_t                    g_HandledSignals;

void
WatchSignals()
{
  int signalNumber = 0;
  while (sigwait(&g_HandledSignals, &signalNumber) != 0)
  {}
  // Kept locked: no commit may start while the process ends.
  g_CleanupMutex.lock();
  // Temporary directories first, then the (then empty) directories made for them.
  for (const bool recursive : { true, false })
  {
    for (const auto & entry : g_Cleanup)
    {
      if (entry.second.recursive == recursive)
      {
        std::error_code error;
        if (recursive)
        {
          fs::remove_all(entry.second.path, error);
        }
        else
        {
          fs::remove(entry.second.path, error);
        }
      }
    }
  }
  std::signal(signalNumber, SIG_DFL);
  sigset_t one;
  sigemptyset(&one);
  sigaddset(&one, signalNumber);
  pthread_sigmask(SIG_UNBLOCK, &one, nullptr);
  raise(signalNumber);
  _exit(128 + signalNumber);
}

int
RegisterCleanup(const std::string & path, bool recursive)
{
  std::lock_guard<std::mutex> lock(g_CleanupMutex);
  const int                   id = g_NextCleanup++;
  g_Cleanup[id] = CleanupEntry{ path, recursive };
  return id;
}

void
UnregisterCleanup(int id)
{
  if (id >= 0)
  {
    std::lock_guard<std::mutex> lock(g_CleanupMutex);
    g_Cleanup.erase(id);
  }
}

// --- Messages of third-party libraries -------------------------------------

/** Redirects file descriptors 1 and 2 to a temporary file while it lives:
 * MetaIO, GIFTI, GDCM, NIfTI and NRRD print their complaints there. Text()
 * gives what they printed, folded into one line. */
class CapturedOutput
{
public:
  CapturedOutput()
  {
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    m_File = std::tmpfile();
    if (m_File == nullptr)
    {
      return;
    }
    m_SavedOut = dup(1);
    m_SavedErr = dup(2);
    dup2(fileno(m_File), 1);
    dup2(fileno(m_File), 2);
  }
  ~CapturedOutput() { this->Restore(); }
  CapturedOutput(const CapturedOutput &) = delete;
  CapturedOutput &
  operator=(const CapturedOutput &) = delete;

  /** Stops capturing and returns what was printed, in one line. */
  std::string
  Text()
  {
    this->Restore();
    return m_Text;
  }

private:
  void
  Restore()
  {
    if (m_File == nullptr)
    {
      return;
    }
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    dup2(m_SavedOut, 1);
    dup2(m_SavedErr, 2);
    close(m_SavedOut);
    close(m_SavedErr);
    std::rewind(m_File);
    std::string text;
    char        buffer[4096];
    size_t      n = 0;
    while ((n = std::fread(buffer, 1, sizeof(buffer), m_File)) > 0 && text.size() < 65536)
    {
      text.append(buffer, n);
    }
    std::fclose(m_File);
    m_File = nullptr;
    m_Text = text.empty() ? std::string() : OneLine(text);
    if (m_Text == "unknown error")
    {
      m_Text.clear();
    }
  }

  std::FILE * m_File{ nullptr };
  int         m_SavedOut{ -1 };
  int         m_SavedErr{ -1 };
  std::string m_Text;
};

/** The message of an exception, with what the library printed appended. */
std::string
Describe(const itk::ExceptionObject & exception, const std::string & printed)
{
  std::string text = OneLine(exception.GetDescription());
  if (!printed.empty() && text.find(printed) == std::string::npos)
  {
    text += (text.empty() || text.back() == ':' ? " " : ": ") + printed;
  }
  return text;
}

// --- Files -----------------------------------------------------------------

/** A regular, readable file, or Error naming what it is instead: opening a
 * FIFO or a device would block or read forever. */
void
RequireRegularFile(const std::string & path, const std::string & what)
{
  struct stat status;
  if (stat(path.c_str(), &status) != 0)
  {
    throw Error("cannot read " + what + " " + Quote(path) + ": " +
                (errno == ENOENT ? std::string("no such file or directory") : std::strerror(errno)));
  }
  if (!S_ISREG(status.st_mode))
  {
    throw Error("cannot read " + what + " " + Quote(path) + ": not a regular file (" +
                (S_ISFIFO(status.st_mode)   ? "a FIFO"
                 : S_ISCHR(status.st_mode)  ? "a character device"
                 : S_ISBLK(status.st_mode)  ? "a block device"
                 : S_ISSOCK(status.st_mode) ? "a socket"
                                            : "not a file") +
                ")");
  }
  if (access(path.c_str(), R_OK) != 0)
  {
    throw Error("cannot read " + what + " " + Quote(path) + ": " + std::strerror(errno));
  }
}

std::uintmax_t
FileSize(const std::string & path)
{
  std::error_code error;
  const auto      size = fs::file_size(path, error);
  return error ? 0 : size;
}

std::string
ReadWholeFile(const std::string & path, const std::string & what)
{
  std::ifstream stream(path, std::ios::binary);
  if (!stream)
  {
    throw Error("cannot read " + what + " " + Quote(path) + ": " + std::strerror(errno));
  }
  std::string data(FileSize(path), '\0');
  stream.read(&data[0], static_cast<std::streamsize>(data.size()));
  data.resize(static_cast<size_t>(stream.gcount()));
  return data;
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
  const long nameMax = pathconf(directory.c_str(), _PC_NAME_MAX);
  const auto name = p.filename().string();
  if (nameMax > 0 && name.size() > static_cast<size_t>(nameMax))
  {
    throw Error(option + ": the file name " + Quote(name.substr(0, 40) + "...") + " has " +
                std::to_string(name.size()) + " characters, more than the file system allows (" +
                std::to_string(nameMax) + ")");
  }
}

/** After a writer returned: the files of \a directory reached the disk, and
 * the file system did not run out of space (some writers, ITK's among them,
 * do not check their writes: a full disk leaves a short file). */
void
VerifyWrittenFiles(const std::string & directory, const std::string & finalPath)
{
  std::error_code error;
  bool            any = false;
  for (const auto & entry : fs::directory_iterator(directory, error))
  {
    const int descriptor = open(entry.path().c_str(), O_RDONLY);
    if (descriptor < 0 || fsync(descriptor) != 0)
    {
      const int code = errno;
      if (descriptor >= 0)
      {
        close(descriptor);
      }
      throw Error("cannot write " + Quote(finalPath) + ": " + std::strerror(code));
    }
    close(descriptor);
    any = true;
  }
  if (!any)
  {
    throw Error("cannot write " + Quote(finalPath) + ": the writer produced no file");
  }
  struct statvfs fileSystem;
  if (statvfs(directory.c_str(), &fileSystem) == 0)
  {
    const double freeBytes =
      static_cast<double>(geteuid() == 0 ? fileSystem.f_bfree : fileSystem.f_bavail) * fileSystem.f_frsize;
    if (freeBytes < 65536.0)
    {
      throw Error("cannot write " + Quote(finalPath) + ": no space left on device (the file system is full)");
    }
  }
}

/** Writes \a data to \a path, checking every call (a full disk is an Error). */
void
WriteFileChecked(const std::string & data, const std::string & path, const std::string & finalPath)
{
  std::FILE * file = std::fopen(path.c_str(), "wb");
  if (file == nullptr)
  {
    throw Error("cannot write " + Quote(finalPath) + ": " + std::strerror(errno));
  }
  const size_t written = std::fwrite(data.data(), 1, data.size(), file);
  int          code = written == data.size() ? 0 : errno;
  if (std::fflush(file) != 0 && code == 0)
  {
    code = errno;
  }
  if (std::fclose(file) != 0 && code == 0)
  {
    code = errno;
  }
  if (code != 0 || written != data.size())
  {
    std::remove(path.c_str());
    throw Error("cannot write " + Quote(finalPath) + ": " + std::strerror(code != 0 ? code : EIO));
  }
}

// --- Memory ----------------------------------------------------------------

/** Bytes this process may still allocate: the address-space limit
 * (ulimit -v) less what it uses, and the memory the system has available. */
double
AvailableMemory()
{
  double        available = std::numeric_limits<double>::infinity();
  struct rlimit limit;
  if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
  {
    double        used = 0.0;
    std::ifstream statm("/proc/self/statm");
    double        pages = 0.0;
    if (statm >> pages)
    {
      used = pages * static_cast<double>(sysconf(_SC_PAGESIZE));
    }
    available = std::max(0.0, static_cast<double>(limit.rlim_cur) - used);
  }
  std::ifstream meminfo("/proc/meminfo");
  std::string   key;
  double        value = 0.0;
  std::string   unit;
  double        system = 0.0;
  bool          found = false;
  while (meminfo >> key >> value >> unit)
  {
    if (key == "MemAvailable:" || key == "SwapFree:")
    {
      system += value * 1024.0;
      found = true;
    }
  }
  return found ? std::min(available, system) : available;
}

// --- Images ----------------------------------------------------------------

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

std::string
FormatNumber(double value)
{
  std::ostringstream stream;
  stream << value;
  return stream.str();
}

/** "Key = Value" or "key: value" header lines of a text header, up to the
 * first line that is neither (or the end of the first 64 KB). \a end is the
 * offset of the byte after the last header line read. */
std::map<std::string, std::string>
ReadTextHeader(const std::string & path, char separator, std::uintmax_t & end, const std::string & lastKey)
{
  std::map<std::string, std::string> fields;
  std::ifstream                      stream(path, std::ios::binary);
  std::string                        line;
  end = 0;
  while (end < 65536 && std::getline(stream, line))
  {
    const std::uintmax_t next = end + line.size() + 1;
    if (!line.empty() && line.back() == '\r')
    {
      line.pop_back();
    }
    const auto position = line.find(separator);
    if (line.empty() || (position == std::string::npos && line[0] != '#' && line.compare(0, 4, "NRRD") != 0))
    {
      end = next;
      break;
    }
    end = next;
    if (position == std::string::npos || line[0] == '#')
    {
      continue;
    }
    auto trim = [](std::string text) {
      while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
      {
        text.pop_back();
      }
      size_t first = 0;
      while (first < text.size() && std::isspace(static_cast<unsigned char>(text[first])))
      {
        ++first;
      }
      return text.substr(first);
    };
    std::string key = trim(line.substr(0, position));
    std::transform(key.begin(), key.end(), key.begin(), [](unsigned char c) { return std::tolower(c); });
    // NRRD's "key:=value" lines are key/value pairs of the user.
    const std::string value = trim(line.substr(position + 1));
    fields[key] = value;
    if (key == lastKey)
    {
      break;
    }
  }
  return fields;
}

#ifdef EDM_HAVE_ZLIB
/** Inflates the zlib or gzip stream that starts at \a offset in \a path
 * until \a needed bytes came out (true) or the data ended first (false). */
bool
InflatesTo(const std::string & path, std::uintmax_t offset, std::uintmax_t needed, std::string & problem)
{
  std::ifstream stream(path, std::ios::binary);
  stream.seekg(static_cast<std::streamoff>(offset));
  z_stream z;
  std::memset(&z, 0, sizeof(z));
  if (inflateInit2(&z, 15 + 32) != Z_OK) // zlib or gzip header
  {
    problem = "cannot start zlib";
    return false;
  }
  std::vector<unsigned char> in(1 << 16);
  std::vector<unsigned char> out(1 << 18);
  std::uintmax_t             total = 0;
  int                        status = Z_OK;
  while (total < needed)
  {
    if (z.avail_in == 0)
    {
      stream.read(reinterpret_cast<char *>(in.data()), static_cast<std::streamsize>(in.size()));
      z.avail_in = static_cast<uInt>(stream.gcount());
      z.next_in = in.data();
      if (z.avail_in == 0)
      {
        problem = "the compressed data ends after " + std::to_string(total) + " of the " + std::to_string(needed) +
                  " bytes the header announces (truncated file)";
        break;
      }
    }
    z.avail_out = static_cast<uInt>(out.size());
    z.next_out = out.data();
    status = inflate(&z, Z_NO_FLUSH);
    total += out.size() - z.avail_out;
    if (status == Z_STREAM_END)
    {
      if (total < needed)
      {
        problem = "the compressed data holds " + std::to_string(total) + " of the " + std::to_string(needed) +
                  " bytes the header announces (truncated file)";
      }
      break;
    }
    if (status != Z_OK && status != Z_BUF_ERROR)
    {
      problem = std::string("corrupt compressed data (") + (z.msg != nullptr ? z.msg : "zlib error") + ")";
      break;
    }
  }
  inflateEnd(&z);
  return total >= needed && problem.empty();
}
#endif

/** NIfTI's library replaces NaN and infinite voxels by 0 as it reads them:
 * the float voxels of a .nii or .nii.gz are checked here first. */
void
CheckNiftiFloats(const std::string & path, const itk::ImageIOBase * io)
{
  const bool compressed = GetExtension(path) == ".nii.gz";
  if (compressed)
  {
#ifndef EDM_HAVE_ZLIB
    return;
#endif
  }
  unsigned char header[348] = {};
  std::string   bytes;
#ifdef EDM_HAVE_ZLIB
  gzFile file = compressed ? gzopen(path.c_str(), "rb") : nullptr;
  if (compressed && (file == nullptr || gzread(file, header, sizeof(header)) != static_cast<int>(sizeof(header))))
  {
    if (file != nullptr)
    {
      gzclose(file);
    }
    return;
  }
#endif
  std::ifstream stream;
  if (!compressed)
  {
    stream.open(path, std::ios::binary);
    stream.read(reinterpret_cast<char *>(header), sizeof(header));
  }
  std::int32_t sizeOfHeader = 0;
  std::memcpy(&sizeOfHeader, header, 4);
  const bool swapped = sizeOfHeader != 348;
  auto       swap = [swapped](unsigned char * p, size_t n) {
    if (swapped)
    {
      std::reverse(p, p + n);
    }
  };
  swap(header + 70, 2);
  swap(header + 108, 4);
  std::int16_t datatype = 0;
  float        voxelOffset = 0.0f;
  std::memcpy(&datatype, header + 70, 2);
  std::memcpy(&voxelOffset, header + 108, 4);
  const size_t               size = datatype == 16 ? 4 : datatype == 64 ? 8 : 0;
  const bool                 valid = (sizeOfHeader == 348 || swapped) && size != 0 && voxelOffset >= 348.0f;
  std::uintmax_t             position = sizeof(header);
  const auto                 skip = static_cast<std::uintmax_t>(valid ? voxelOffset : 0.0f);
  const std::uintmax_t       count = io->GetImageSizeInBytes() / std::max<size_t>(size, 1);
  std::vector<unsigned char> buffer(size * 65536);
  std::uintmax_t             voxel = 0;
  auto                       read = [&](unsigned char * into, size_t n) -> size_t {
#ifdef EDM_HAVE_ZLIB
    if (compressed)
    {
      const int got = gzread(file, into, static_cast<unsigned int>(n));
      return got > 0 ? static_cast<size_t>(got) : 0;
    }
#endif
    stream.read(reinterpret_cast<char *>(into), static_cast<std::streamsize>(n));
    return static_cast<size_t>(stream.gcount());
  };
  std::string problem;
  if (valid)
  {
    // To the first voxel.
    std::vector<unsigned char> gap(skip > position ? skip - position : 0);
    position += read(gap.data(), gap.size());
    while (voxel < count && problem.empty())
    {
      const size_t want = static_cast<size_t>(std::min<std::uintmax_t>(count - voxel, 65536)) * size;
      const size_t got = read(buffer.data(), want) / size;
      if (got == 0)
      {
        break;
      }
      for (size_t i = 0; i < got; ++i, ++voxel)
      {
        unsigned char * p = buffer.data() + i * size;
        swap(p, size);
        double value = 0.0;
        if (size == 4)
        {
          float f;
          std::memcpy(&f, p, 4);
          value = f;
        }
        else
        {
          std::memcpy(&value, p, 8);
        }
        if (!std::isfinite(value))
        {
          const std::uintmax_t nx = io->GetDimensions(0);
          const std::uintmax_t ny = io->GetDimensions(1);
          problem = "image " + Quote(path) + " has a non-finite value (" + FormatNumber(value) + ") at voxel (" +
                    std::to_string(voxel % nx) + ", " + std::to_string(voxel / nx % ny) + ", " +
                    std::to_string(voxel / nx / ny) + ")";
          break;
        }
      }
    }
  }
#ifdef EDM_HAVE_ZLIB
  if (compressed)
  {
    gzclose(file);
  }
#endif
  if (!problem.empty())
  {
    throw Error(problem);
  }
}

/** Refuses an image file whose data is shorter than its header announces:
 * ITK's readers fill the missing voxels with zeros or stop silently. Checks
 * MetaImage, NIfTI and NRRD (raw and gzip data); other formats pass. */
void
CheckImageData(const std::string & path, const itk::ImageIOBase * io)
{
  const std::uintmax_t needed = io->GetImageSizeInBytes();
  const std::string    extension = GetExtension(path);
  const std::string    name = io->GetNameOfClass();
  std::string          dataPath;
  std::uintmax_t       offset = 0;
  bool                 atEnd = false; // offset unknown: the data ends the file
  bool                 compressed = false;
  std::uintmax_t       compressedSize = 0;

  if (name == "MetaImageIO")
  {
    std::uintmax_t headerEnd = 0;
    auto           fields = ReadTextHeader(path, '=', headerEnd, "elementdatafile");
    const auto     data = fields["elementdatafile"];
    compressed = fields["compresseddata"] == "True" || fields["compresseddata"] == "true";
    if (fields.count("compresseddatasize") != 0)
    {
      compressedSize = std::strtoull(fields["compresseddatasize"].c_str(), nullptr, 10);
    }
    if (data == "LOCAL" || data == "Local" || data == "local")
    {
      dataPath = path;
      offset = headerEnd;
    }
    else if (data.empty() || data.compare(0, 4, "LIST") == 0 || data.find('%') != std::string::npos ||
             data.find(' ') != std::string::npos)
    {
      return;
    }
    else
    {
      dataPath = (fs::path(path).parent_path() / data).string();
      const long long headerSize =
        fields.count("headersize") != 0 ? std::strtoll(fields["headersize"].c_str(), nullptr, 10) : 0;
      atEnd = headerSize < 0;
      offset = headerSize > 0 ? static_cast<std::uintmax_t>(headerSize) : 0;
    }
  }
  else if (name == "NrrdImageIO")
  {
    std::uintmax_t headerEnd = 0;
    auto           fields = ReadTextHeader(path, ':', headerEnd, "");
    const auto     encoding = fields["encoding"];
    if (encoding == "gzip" || encoding == "gz")
    {
      compressed = true;
    }
    else if (encoding != "raw")
    {
      return;
    }
    const std::string data = fields.count("data file") != 0 ? fields["data file"] : fields["datafile"];
    if (data.empty())
    {
      dataPath = path;
      offset = headerEnd;
    }
    else if (data.compare(0, 4, "LIST") == 0 || data.find(' ') != std::string::npos ||
             data.find('%') != std::string::npos)
    {
      return;
    }
    else
    {
      dataPath = fs::path(data).is_absolute() ? data : (fs::path(path).parent_path() / data).string();
    }
    const std::string skip = fields.count("byte skip") != 0 ? fields["byte skip"] : fields["byteskip"];
    if (!skip.empty())
    {
      const long long bytes = std::strtoll(skip.c_str(), nullptr, 10);
      atEnd = bytes < 0;
      offset += bytes > 0 ? static_cast<std::uintmax_t>(bytes) : 0;
    }
  }
  else if (name == "NiftiImageIO")
  {
    if (extension == ".nii.gz")
    {
#ifdef EDM_HAVE_ZLIB
      // The header tells where the voxels start; the whole must inflate.
      gzFile file = gzopen(path.c_str(), "rb");
      if (file == nullptr)
      {
        return;
      }
      unsigned char header[348];
      const int     got = gzread(file, header, sizeof(header));
      gzclose(file);
      std::int32_t sizeOfHeader = 0;
      std::memcpy(&sizeOfHeader, header, 4);
      std::uintmax_t voxelOffset = 352;
      if (got == static_cast<int>(sizeof(header)) && sizeOfHeader == 348)
      {
        float value = 0.0f;
        std::memcpy(&value, header + 108, 4);
        voxelOffset = value >= 348.0f ? static_cast<std::uintmax_t>(value) : 352;
      }
      else if (got == static_cast<int>(sizeof(header)) && sizeOfHeader == 540)
      {
        voxelOffset = 544;
      }
      std::string problem;
      if (!InflatesTo(path, 0, voxelOffset + needed, problem))
      {
        throw Error("cannot read image " + Quote(path) + ": " + problem);
      }
      CheckNiftiFloats(path, io);
#endif
      return;
    }
    if (extension != ".nii")
    {
      return;
    }
    dataPath = path;
    std::ifstream stream(path, std::ios::binary);
    unsigned char header[348] = {};
    stream.read(reinterpret_cast<char *>(header), sizeof(header));
    std::int32_t sizeOfHeader = 0;
    std::memcpy(&sizeOfHeader, header, 4);
    float value = 0.0f;
    std::memcpy(&value, header + 108, 4);
    if (sizeOfHeader == 348 && value >= 348.0f)
    {
      offset = static_cast<std::uintmax_t>(value);
    }
    else
    {
      atEnd = true;
    }
    if (FileSize(path) >= offset + needed)
    {
      CheckNiftiFloats(path, io);
    }
  }
  else
  {
    return;
  }

  const std::uintmax_t size = FileSize(dataPath);
  if (compressed)
  {
    if (compressedSize > 0 && size < offset + compressedSize)
    {
      throw Error("cannot read image " + Quote(path) + ": truncated: " + std::to_string(size - std::min(size, offset)) +
                  " of the " + std::to_string(compressedSize) + " bytes of compressed data its header announces");
    }
#ifdef EDM_HAVE_ZLIB
    std::string problem;
    if (!InflatesTo(dataPath, offset, needed, problem))
    {
      throw Error("cannot read image " + Quote(path) + ": " + problem);
    }
#endif
    return;
  }
  const std::uintmax_t present = atEnd ? size : size - std::min(size, offset);
  if (present < needed)
  {
    throw Error("cannot read image " + Quote(path) +
                ": truncated: " + (dataPath == path ? std::string() : "its data file " + Quote(dataPath) + " holds ") +
                std::to_string(present) + " of the " + std::to_string(needed) +
                " bytes of voxels its header announces (" +
                DescribeSize({ io->GetDimensions(0), io->GetDimensions(1), io->GetDimensions(2) }) + " voxels of " +
                std::to_string(io->GetComponentSize() * io->GetNumberOfComponents()) + " bytes)");
  }
}

/** Spacing and origin that the physical-space computations can hold (the
 * first three axes, or the two of a 2-D image). */
void
CheckImageGeometry(const std::string & path, const itk::ImageIOBase * io)
{
  const unsigned int dimension = std::min(3u, io->GetNumberOfDimensions());
  const auto         list = [dimension](const std::function<double(unsigned int)> & value, const char * separator) {
    std::string text;
    for (unsigned int d = 0; d < dimension; ++d)
    {
      text += (d == 0 ? "" : separator) + FormatNumber(value(d));
    }
    return text;
  };
  for (unsigned int d = 0; d < dimension; ++d)
  {
    const double spacing = io->GetSpacing(d);
    if (!(spacing >= 1e-9 && spacing <= 1e9))
    {
      throw Error("image " + Quote(path) + " has spacing " +
                  list([io](unsigned int k) { return io->GetSpacing(k); }, " x ") +
                  ": edmodel needs spacings between 1e-09 and 1e+09 (physical units per voxel)");
    }
    const double origin = io->GetOrigin(d);
    if (!(std::abs(origin) <= 1e12))
    {
      throw Error("image " + Quote(path) + " has origin " +
                  list([io](unsigned int k) { return io->GetOrigin(k); }, ", ") +
                  ": edmodel needs coordinates within 1e+12 of 0");
    }
  }
}

void
CheckMemoryForImage(const std::string & path, const std::vector<size_t> & size, double bytesPerVoxel)
{
  double voxels = 1.0;
  for (const auto n : size)
  {
    voxels *= static_cast<double>(n);
  }
  const double needed = voxels * bytesPerVoxel;
  const double available = AvailableMemory();
  if (needed > available)
  {
    throw Error("image " + Quote(path) + " is " + DescribeSize(size) + " voxels: the run needs about " +
                FormatBytes(needed) + " of memory, and " + FormatBytes(available) + " are available");
  }
}

/** The first voxel of \a image that is not finite, as an Error. */
template <typename TImage>
void
CheckFiniteVoxels(const std::string & path, const TImage * image)
{
  const float *            voxels = image->GetBufferPointer();
  const itk::SizeValueType n = image->GetBufferedRegion().GetNumberOfPixels();
  for (itk::SizeValueType i = 0; i < n; ++i)
  {
    if (!std::isfinite(voxels[i]))
    {
      const auto  index = image->ComputeIndex(static_cast<itk::OffsetValueType>(i));
      std::string where;
      for (unsigned int d = 0; d < TImage::ImageDimension; ++d)
      {
        where += (d == 0 ? "" : ", ") + std::to_string(index[d]);
      }
      throw Error("image " + Quote(path) + " has a non-finite value (" + FormatNumber(voxels[i]) + ") at voxel (" +
                  where + ")");
    }
  }
}

/** Double images are read as double and checked against the float range that
 * edmodel computes in (a cast would turn 1e300 into infinity). */
template <typename TImage>
typename TImage::Pointer
ReadDoubleImage(const std::string & path, itk::ImageIOBase * io)
{
  using DoubleImageType = itk::Image<double, TImage::ImageDimension>;
  auto reader = itk::ImageFileReader<DoubleImageType>::New();
  reader->SetImageIO(io);
  reader->SetFileName(path);
  {
    CapturedOutput captured;
    try
    {
      reader->Update();
    }
    catch (const itk::ExceptionObject & exception)
    {
      throw Error("cannot read image " + Quote(path) + ": " + Describe(exception, captured.Text()));
    }
  }
  const DoubleImageType * input = reader->GetOutput();
  auto                    image = TImage::New();
  image->CopyInformation(input);
  image->SetRegions(input->GetBufferedRegion());
  image->Allocate();
  const double *           in = input->GetBufferPointer();
  float *                  out = image->GetBufferPointer();
  const itk::SizeValueType n = input->GetBufferedRegion().GetNumberOfPixels();
  for (itk::SizeValueType i = 0; i < n; ++i)
  {
    if (std::isfinite(in[i]) && std::abs(in[i]) > FLT_MAX)
    {
      throw Error("image " + Quote(path) + " holds values up to " + FormatNumber(in[i]) +
                  ", beyond the range of float (3.4e+38) that edmodel computes in: rescale its intensities");
    }
    out[i] = static_cast<float>(in[i]);
  }
  return image;
}

/** Whether the last Pixel Data element (7FE0,0010) of a DICOM file holds
 * the bytes its length announces (encapsulated, compressed data is not
 * checked); \a held is what the file holds of it. */
bool
PixelDataComplete(const std::string & file, std::uintmax_t & held)
{
  const std::string data = ReadWholeFile(file, "DICOM file");
  const char        tag[4] = { '\xE0', '\x7F', '\x10', '\x00' };
  const auto        position = data.rfind(std::string(tag, 4));
  if (position == std::string::npos)
  {
    return true;
  }
  // Explicit VR (OB, OW: 2 reserved bytes, 4-byte length) or implicit VR.
  const bool explicitVR = position + 8 <= data.size() &&
                          (data.compare(position + 4, 2, "OW") == 0 || data.compare(position + 4, 2, "OB") == 0);
  const size_t  lengthAt = position + (explicitVR ? 8 : 4);
  std::uint32_t length = 0;
  if (lengthAt + 4 > data.size())
  {
    return false;
  }
  std::memcpy(&length, data.data() + lengthAt, 4);
  if (length == 0xFFFFFFFFu)
  {
    return true;
  }
  held = data.size() - (lengthAt + 4);
  return held >= length;
}

ImageType::Pointer
ReadDicomSeries(const std::string & directory)
{
  auto names = itk::GDCMSeriesFileNames::New();
  names->SetUseSeriesDetails(true);
  names->SetDirectory(directory);
  std::vector<std::string> files;
  {
    CapturedOutput captured;
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
      throw Error("cannot read DICOM directory " + Quote(directory) + ": " + Describe(exception, captured.Text()));
    }
  }
  if (files.empty())
  {
    throw Error("cannot read image " + Quote(directory) + ": a directory with no DICOM series");
  }
  // A truncated slice would be read as zeros: every file must hold the pixel
  // data of its rows and columns.
  for (const auto & file : files)
  {
    RequireRegularFile(file, "DICOM file");
    auto io = itk::GDCMImageIO::New();
    io->SetFileName(file);
    CapturedOutput captured;
    try
    {
      io->ReadImageInformation();
    }
    catch (const itk::ExceptionObject & exception)
    {
      throw Error("cannot read DICOM file " + Quote(file) + ": " + Describe(exception, captured.Text()));
    }
    const std::uintmax_t needed = io->GetImageSizeInBytes();
    std::uintmax_t       held = 0;
    if (FileSize(file) < needed || !PixelDataComplete(file, held))
    {
      throw Error("cannot read DICOM series in " + Quote(directory) + ": " + Quote(file) +
                  " is truncated (its pixel data element holds " + std::to_string(held) + " bytes of " +
                  std::to_string(std::max<std::uintmax_t>(needed, held)) + ")");
    }
  }
  using ReaderType = itk::ImageSeriesReader<ImageType>;
  auto reader = ReaderType::New();
  reader->SetImageIO(itk::GDCMImageIO::New());
  reader->SetFileNames(files);
  {
    CapturedOutput captured;
    try
    {
      reader->Update();
    }
    catch (const itk::ExceptionObject & exception)
    {
      throw Error("cannot read DICOM series in " + Quote(directory) + ": " + Describe(exception, captured.Text()));
    }
    const std::string printed = captured.Text();
    if (printed.find("rror") != std::string::npos)
    {
      throw Error("cannot read DICOM series in " + Quote(directory) + ": " + printed);
    }
  }
  ImageType::Pointer image = reader->GetOutput();
  const auto         size = image->GetLargestPossibleRegion().GetSize();
  if (size[2] < 2)
  {
    throw Error("image " + Quote(directory) + " is 2-D (" + DescribeSize({ size[0], size[1] }) +
                ", one DICOM slice): edmodel needs a 3-D volume");
  }
  CheckFiniteVoxels(directory, image.GetPointer());
  return image;
}

// --- Meshes: the project's own readers of .vtk, .off and .obj ----------------
//
// ITK 5.2's readers of these formats loop forever on some malformed files (a
// "nan" token, a count larger than the data, a negative count) and allocate
// whatever a header claims. These readers check every count against the
// file's size before allocating and every token as it is read.

/** Tokens of a text (or mixed text and binary) file, with line numbers. */
class Scanner
{
public:
  Scanner(const std::string & data, const std::string & path)
    : m_Data(data)
    , m_Path(path)
  {}

  [[noreturn]] void
  Fail(const std::string & problem) const
  {
    throw Error("cannot read mesh " + Quote(m_Path) + ": line " + std::to_string(m_Line) + ": " + problem);
  }

  bool
  AtEnd()
  {
    this->SkipSpace();
    return m_Position >= m_Data.size();
  }

  /** The next whitespace-separated token ("" at the end). */
  std::string
  Token()
  {
    this->SkipSpace();
    const size_t start = m_Position;
    while (m_Position < m_Data.size() && !std::isspace(static_cast<unsigned char>(m_Data[m_Position])))
    {
      ++m_Position;
    }
    return m_Data.substr(start, m_Position - start);
  }

  /** The rest of the current line, and the position at the next one. */
  std::string
  RestOfLine()
  {
    const size_t start = m_Position;
    while (m_Position < m_Data.size() && m_Data[m_Position] != '\n')
    {
      ++m_Position;
    }
    std::string line = m_Data.substr(start, m_Position - start);
    if (m_Position < m_Data.size())
    {
      ++m_Position;
      ++m_Line;
    }
    if (!line.empty() && line.back() == '\r')
    {
      line.pop_back();
    }
    return line;
  }

  double
  Number(const char * what)
  {
    const std::string token = this->Token();
    if (token.empty())
    {
      this->Fail(std::string("the file ends where ") + what + " was expected");
    }
    return ParseNumber(token, what);
  }

  double
  ParseNumber(const std::string & token, const char * what) const
  {
    char *       end = nullptr;
    const double value = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0')
    {
      this->Fail(Quote(token) + " is not a number (" + what + ")");
    }
    if (!std::isfinite(value))
    {
      this->Fail(Quote(token) + " is not a finite number (" + what + ")");
    }
    return value;
  }

  /** A non-negative integer no larger than \a largest. */
  std::uint64_t
  Count(const char * what, std::uint64_t largest)
  {
    const std::string token = this->Token();
    return this->ParseCount(token, what, largest);
  }

  std::uint64_t
  ParseCount(const std::string & token, const char * what, std::uint64_t largest) const
  {
    if (token.empty())
    {
      this->Fail(std::string("the file ends where ") + what + " was expected");
    }
    if (token[0] == '-')
    {
      this->Fail(std::string(what) + " is negative (" + token + ")");
    }
    char * end = nullptr;
    errno = 0;
    const unsigned long long value = std::strtoull(token.c_str(), &end, 10);
    if (end == token.c_str() || *end != '\0' || errno == ERANGE)
    {
      this->Fail(Quote(token) + " is not a non-negative integer (" + what + ")");
    }
    if (value > largest)
    {
      this->Fail(std::string(what) + " " + token + " is more than the file of " + std::to_string(m_Data.size()) +
                 " bytes can hold (at most " + std::to_string(largest) + ")");
    }
    return value;
  }

  /** Binary data: after the end of the current header line. */
  void
  SkipToNextLine()
  {
    while (m_Position < m_Data.size() && m_Data[m_Position] != '\n')
    {
      ++m_Position;
    }
    if (m_Position < m_Data.size())
    {
      ++m_Position;
      ++m_Line;
    }
  }

  const unsigned char *
  Bytes(size_t count)
  {
    if (count > m_Data.size() - std::min(m_Position, m_Data.size()))
    {
      this->Fail("the binary data ends " + std::to_string(count - (m_Data.size() - m_Position)) +
                 " bytes before the counts of the header say");
    }
    const auto * bytes = reinterpret_cast<const unsigned char *>(m_Data.data() + m_Position);
    m_Position += count;
    return bytes;
  }

  size_t
  Remaining() const
  {
    return m_Data.size() - std::min(m_Position, m_Data.size());
  }

  size_t
  Size() const
  {
    return m_Data.size();
  }

private:
  void
  SkipSpace()
  {
    while (m_Position < m_Data.size() && std::isspace(static_cast<unsigned char>(m_Data[m_Position])))
    {
      m_Line += m_Data[m_Position] == '\n' ? 1 : 0;
      ++m_Position;
    }
  }

  const std::string & m_Data;
  const std::string & m_Path;
  size_t              m_Position{ 0 };
  size_t              m_Line{ 1 };
};

using CellAutoPointer = MeshType::CellType::CellAutoPointer;

/** Cells of the readers, as itk::Mesh cells. */
class MeshBuilder
{
public:
  explicit MeshBuilder(const std::string & path)
    : m_Mesh(MeshType::New())
    , m_Path(path)
  {}

  void
  ReservePoints(std::uint64_t n)
  {
    auto points = MeshType::PointsContainer::New();
    points->Reserve(n);
    m_Mesh->SetPoints(points);
    m_NumberOfPoints = n;
  }

  void
  SetPoint(std::uint64_t i, double x, double y, double z)
  {
    auto & p = m_Mesh->GetPoints()->ElementAt(i);
    p[0] = x;
    p[1] = y;
    p[2] = z;
  }

  /** A cell of \a ids (already checked against the number of points):
   * vertex, line segments (a polyline is cut into segments), triangle or
   * polygon. */
  void
  AddCell(const std::vector<std::uint64_t> & ids, bool curve)
  {
    std::vector<MeshType::PointIdentifier> identifiers(ids.begin(), ids.end());
    if (curve && ids.size() > 2)
    {
      for (size_t k = 0; k + 1 < ids.size(); ++k)
      {
        this->AddCell({ ids[k], ids[k + 1] }, true);
      }
      return;
    }
    CellAutoPointer cell;
    if (ids.size() == 1)
    {
      cell.TakeOwnership(new itk::VertexCell<MeshType::CellType>);
    }
    else if (ids.size() == 2)
    {
      cell.TakeOwnership(new itk::LineCell<MeshType::CellType>);
    }
    else if (ids.size() == 3)
    {
      cell.TakeOwnership(new itk::TriangleCell<MeshType::CellType>);
    }
    else
    {
      cell.TakeOwnership(new itk::PolygonCell<MeshType::CellType>);
      cell->SetPointIds(identifiers.data(), identifiers.data() + identifiers.size());
      m_Mesh->SetCell(m_NumberOfCells++, cell);
      return;
    }
    cell->SetPointIds(identifiers.data());
    m_Mesh->SetCell(m_NumberOfCells++, cell);
  }

  MeshType::Pointer
  GetMesh()
  {
    return m_Mesh;
  }

  std::uint64_t
  GetNumberOfPoints() const
  {
    return m_NumberOfPoints;
  }

private:
  MeshType::Pointer m_Mesh;
  std::string       m_Path;
  std::uint64_t     m_NumberOfPoints{ 0 };
  std::uint64_t     m_NumberOfCells{ 0 };
};

/** Big-endian binary values of a legacy VTK file, as double. */
double
BigEndianValue(const unsigned char * bytes, const std::string & type)
{
  auto load = [bytes](size_t size) {
    std::uint64_t value = 0;
    for (size_t k = 0; k < size; ++k)
    {
      value = (value << 8) | bytes[k];
    }
    return value;
  };
  if (type == "float")
  {
    const auto bits = static_cast<std::uint32_t>(load(4));
    float      value;
    std::memcpy(&value, &bits, 4);
    return value;
  }
  if (type == "double")
  {
    const std::uint64_t bits = load(8);
    double              value;
    std::memcpy(&value, &bits, 8);
    return value;
  }
  if (type == "int" || type == "vtktypeint32" || type == "vtkidtype")
  {
    return static_cast<double>(static_cast<std::int32_t>(load(4)));
  }
  if (type == "unsigned_int" || type == "vtktypeuint32")
  {
    return static_cast<double>(static_cast<std::uint32_t>(load(4)));
  }
  if (type == "long" || type == "vtktypeint64")
  {
    return static_cast<double>(static_cast<std::int64_t>(load(8)));
  }
  if (type == "unsigned_long" || type == "vtktypeuint64")
  {
    return static_cast<double>(load(8));
  }
  if (type == "short")
  {
    return static_cast<double>(static_cast<std::int16_t>(load(2)));
  }
  if (type == "unsigned_short")
  {
    return static_cast<double>(static_cast<std::uint16_t>(load(2)));
  }
  if (type == "char")
  {
    return static_cast<double>(static_cast<std::int8_t>(load(1)));
  }
  return static_cast<double>(load(1)); // unsigned_char, bit
}

size_t
BinarySize(const std::string & type, const Scanner & scanner)
{
  if (type == "double" || type == "long" || type == "unsigned_long" || type == "vtktypeint64" ||
      type == "vtktypeuint64")
  {
    return 8;
  }
  if (type == "float" || type == "int" || type == "unsigned_int" || type == "vtktypeint32" || type == "vtktypeuint32" ||
      type == "vtkidtype")
  {
    return 4;
  }
  if (type == "short" || type == "unsigned_short")
  {
    return 2;
  }
  if (type == "char" || type == "unsigned_char")
  {
    return 1;
  }
  scanner.Fail("unknown data type " + Quote(type));
}

/** Legacy VTK POLYDATA, ASCII or BINARY, file versions up to 5.1 (OFFSETS
 * and CONNECTIVITY). Attributes after the cells (POINT_DATA, CELL_DATA) are
 * not needed and not read. */
MeshType::Pointer
ReadLegacyVTK(const std::string & path)
{
  const std::string data = ReadWholeFile(path, "mesh");
  Scanner           scan(data, path);
  const std::string version = scan.RestOfLine();
  if (version.compare(0, 22, "# vtk DataFile Version") != 0)
  {
    scan.Fail("not a legacy VTK file (it must start with '# vtk DataFile Version')");
  }
  const bool newCells = std::atof(version.c_str() + 22) >= 5.0;
  scan.RestOfLine(); // title
  std::string format = scan.Token();
  std::transform(format.begin(), format.end(), format.begin(), [](unsigned char c) { return std::toupper(c); });
  if (format != "ASCII" && format != "BINARY")
  {
    scan.Fail("expected ASCII or BINARY, found " + Quote(format));
  }
  const bool  binary = format == "BINARY";
  std::string keyword = scan.Token();
  std::string dataset = scan.Token();
  std::transform(dataset.begin(), dataset.end(), dataset.begin(), [](unsigned char c) { return std::toupper(c); });
  if (keyword != "DATASET" || dataset != "POLYDATA")
  {
    scan.Fail("edmodel reads legacy VTK POLYDATA, found " + Quote(keyword + " " + dataset));
  }

  // Reads count values of type into values (ASCII or big-endian binary).
  auto readValues = [&](std::uint64_t count, std::string type, const char * what, std::vector<double> & values) {
    std::transform(type.begin(), type.end(), type.begin(), [](unsigned char c) { return std::tolower(c); });
    const size_t size = BinarySize(type, scan);
    // At least two bytes per ASCII value ("0 "), size bytes per binary one.
    const std::uint64_t largest = scan.Remaining() / (binary ? size : 2) + 1;
    if (count > largest)
    {
      scan.Fail(std::string("the header announces ") + std::to_string(count) + " " + what + ", more than the " +
                std::to_string(scan.Remaining()) + " bytes left in the file can hold");
    }
    values.resize(count);
    if (binary)
    {
      scan.SkipToNextLine();
      const unsigned char * bytes = scan.Bytes(count * size);
      for (std::uint64_t i = 0; i < count; ++i)
      {
        values[i] = BigEndianValue(bytes + i * size, type);
        if (!std::isfinite(values[i]))
        {
          scan.Fail(std::string("a non-finite value among the ") + what);
        }
      }
    }
    else
    {
      for (std::uint64_t i = 0; i < count; ++i)
      {
        values[i] = scan.Number(what);
      }
    }
  };

  MeshBuilder         builder(path);
  bool                havePoints = false;
  std::vector<double> values;
  std::vector<double> offsets;
  while (!scan.AtEnd())
  {
    std::string section = scan.Token();
    std::transform(section.begin(), section.end(), section.begin(), [](unsigned char c) { return std::toupper(c); });
    if (section == "POINTS")
    {
      const std::uint64_t n = scan.Count("the number of points", scan.Size() / 2);
      const std::string   type = scan.Token();
      readValues(3 * n, type, "point coordinates", values);
      builder.ReservePoints(n);
      for (std::uint64_t i = 0; i < n; ++i)
      {
        builder.SetPoint(i, values[3 * i], values[3 * i + 1], values[3 * i + 2]);
      }
      havePoints = true;
    }
    else if (section == "VERTICES" || section == "LINES" || section == "POLYGONS" || section == "TRIANGLE_STRIPS")
    {
      if (!havePoints)
      {
        scan.Fail(section + " before POINTS");
      }
      const std::uint64_t                     first = scan.Count("the number of cells", scan.Size());
      const std::uint64_t                     second = scan.Count("the size of the cell list", scan.Size());
      std::vector<std::vector<std::uint64_t>> cells;
      auto                                    check = [&](double id) {
        if (!(id >= 0.0 && id < static_cast<double>(builder.GetNumberOfPoints())) || id != std::floor(id))
        {
          scan.Fail(section + " refers to point " + FormatNumber(id) + ", but the file has " +
                    std::to_string(builder.GetNumberOfPoints()) + " points");
        }
        return static_cast<std::uint64_t>(id);
      };
      if (newCells)
      {
        // OFFSETS (first values) then CONNECTIVITY (second values).
        if (scan.Token() != "OFFSETS")
        {
          scan.Fail("expected OFFSETS after " + section);
        }
        readValues(first, scan.Token(), "cell offsets", offsets);
        if (scan.Token() != "CONNECTIVITY")
        {
          scan.Fail("expected CONNECTIVITY after the OFFSETS of " + section);
        }
        readValues(second, scan.Token(), "cell point ids", values);
        for (std::uint64_t c = 0; c + 1 < first; ++c)
        {
          if (!(offsets[c] >= 0.0 && offsets[c] <= offsets[c + 1] && offsets[c + 1] <= static_cast<double>(second)))
          {
            scan.Fail("the OFFSETS of " + section + " are not increasing within the CONNECTIVITY");
          }
          std::vector<std::uint64_t> ids;
          for (auto k = static_cast<std::uint64_t>(offsets[c]); k < static_cast<std::uint64_t>(offsets[c + 1]); ++k)
          {
            ids.push_back(check(values[k]));
          }
          cells.push_back(ids);
        }
      }
      else
      {
        if (first > second)
        {
          scan.Fail(section + " announces " + std::to_string(first) + " cells in a list of " + std::to_string(second) +
                    " values");
        }
        readValues(second, "int", "cell values", values);
        std::uint64_t k = 0;
        for (std::uint64_t c = 0; c < first; ++c)
        {
          if (k >= second || !(values[k] >= 0.0) || values[k] > static_cast<double>(second - k - 1))
          {
            scan.Fail("cell " + std::to_string(c) + " of " + section + " runs past the cell list");
          }
          const auto                 count = static_cast<std::uint64_t>(values[k++]);
          std::vector<std::uint64_t> ids;
          for (std::uint64_t j = 0; j < count; ++j)
          {
            ids.push_back(check(values[k++]));
          }
          cells.push_back(ids);
        }
      }
      for (const auto & ids : cells)
      {
        if (ids.empty())
        {
          continue;
        }
        if (section == "TRIANGLE_STRIPS")
        {
          for (size_t j = 2; j < ids.size(); ++j)
          {
            if (j % 2 == 0)
            {
              builder.AddCell({ ids[j - 2], ids[j - 1], ids[j] }, false);
            }
            else
            {
              builder.AddCell({ ids[j - 1], ids[j - 2], ids[j] }, false);
            }
          }
        }
        else if (section == "POLYGONS" && ids.size() >= 3)
        {
          builder.AddCell(ids, false);
        }
        else if (section != "POLYGONS")
        {
          builder.AddCell(ids, section == "LINES");
        }
      }
    }
    else if (section == "FIELD")
    {
      scan.Token(); // name
      const std::uint64_t arrays = scan.Count("the number of field arrays", scan.Size());
      for (std::uint64_t a = 0; a < arrays; ++a)
      {
        scan.Token(); // array name
        const std::uint64_t components = scan.Count("the number of components", scan.Size());
        const std::uint64_t tuples = scan.Count("the number of tuples", scan.Size());
        if (components != 0 && tuples > scan.Size() / components)
        {
          scan.Fail("a field array larger than the file");
        }
        readValues(components * tuples, scan.Token(), "field values", values);
      }
    }
    else if (section == "METADATA")
    {
      // Ends at an empty line.
      scan.RestOfLine();
      while (scan.Remaining() > 0 && !scan.RestOfLine().empty())
      {}
    }
    else if (section == "POINT_DATA" || section == "CELL_DATA")
    {
      break;
    }
    else
    {
      scan.Fail("unexpected " + Quote(section) + " in a POLYDATA file");
    }
  }
  if (!havePoints)
  {
    scan.Fail("no POINTS section");
  }
  return builder.GetMesh();
}

/** Object File Format: "OFF", the counts, the vertices, then one face per
 * line ("k i1 ... ik", colours after it ignored). */
MeshType::Pointer
ReadOFF(const std::string & path)
{
  const std::string data = ReadWholeFile(path, "mesh");
  Scanner           scan(data, path);
  const std::string magic = scan.Token();
  if (magic != "OFF" && magic != "COFF" && magic != "NOFF" && magic != "CNOFF")
  {
    scan.Fail("not an OFF file (it must start with 'OFF')");
  }
  // Comments before the counts.
  std::string token = scan.Token();
  while (!token.empty() && token[0] == '#')
  {
    scan.RestOfLine();
    token = scan.Token();
  }
  if (token == "BINARY")
  {
    scan.Fail("binary OFF is not supported (write it as text)");
  }
  // Each vertex takes at least 6 bytes ("0 0 0\n"), each face 8 ("3 0 1 2\n").
  const std::uint64_t vertices = scan.ParseCount(token, "the number of vertices", data.size() / 6);
  const std::uint64_t faces = scan.Count("the number of faces", data.size() / 8);
  scan.Count("the number of edges", std::numeric_limits<std::uint64_t>::max());
  if (vertices * 6 + faces * 8 > data.size())
  {
    scan.Fail("the header announces " + std::to_string(vertices) + " vertices and " + std::to_string(faces) +
              " faces, more than the file of " + std::to_string(data.size()) + " bytes can hold");
  }
  MeshBuilder builder(path);
  builder.ReservePoints(vertices);
  scan.RestOfLine();
  for (std::uint64_t i = 0; i < vertices; ++i)
  {
    const double x = scan.Number("a vertex coordinate");
    const double y = scan.Number("a vertex coordinate");
    const double z = scan.Number("a vertex coordinate");
    builder.SetPoint(i, x, y, z);
    scan.RestOfLine(); // colours, normals
  }
  for (std::uint64_t f = 0; f < faces; ++f)
  {
    if (scan.AtEnd())
    {
      scan.Fail("the file ends after " + std::to_string(f) + " of the " + std::to_string(faces) +
                " faces its header announces");
    }
    const std::uint64_t        count = scan.Count("the number of vertices of a face", vertices);
    std::vector<std::uint64_t> ids;
    for (std::uint64_t k = 0; k < count; ++k)
    {
      const std::uint64_t id = scan.Count("a vertex index", std::numeric_limits<std::uint64_t>::max());
      if (id >= vertices)
      {
        scan.Fail("face " + std::to_string(f) + " refers to vertex " + std::to_string(id) + ", but the file has " +
                  std::to_string(vertices) + " vertices");
      }
      ids.push_back(id);
    }
    scan.RestOfLine(); // colour
    if (ids.size() >= 3)
    {
      builder.AddCell(ids, false);
    }
    else if (!ids.empty())
    {
      builder.AddCell(ids, true);
    }
  }
  if (vertices > 0 && builder.GetMesh()->GetNumberOfPoints() != vertices)
  {
    scan.Fail("fewer vertices than the header announces");
  }
  return builder.GetMesh();
}

/** Wavefront OBJ: "v x y z" and "f i j k ..." lines ("i", "i/t", "i//n",
 * "i/t/n"; negative indices count back from the last vertex read); other
 * lines ignored. */
MeshType::Pointer
ReadOBJ(const std::string & path)
{
  const std::string                       data = ReadWholeFile(path, "mesh");
  Scanner                                 scan(data, path);
  std::vector<double>                     coordinates;
  std::vector<std::vector<std::uint64_t>> faces;
  std::vector<bool>                       curves;
  while (scan.Remaining() > 0)
  {
    std::istringstream line(scan.RestOfLine());
    std::string        kind;
    if (!(line >> kind))
    {
      continue;
    }
    if (kind == "v")
    {
      std::string token;
      for (unsigned int k = 0; k < 3; ++k)
      {
        if (!(line >> token))
        {
          scan.Fail("a vertex needs three coordinates");
        }
        coordinates.push_back(scan.ParseNumber(token, "a vertex coordinate"));
      }
    }
    else if (kind == "f" || kind == "l")
    {
      const auto                 known = static_cast<long long>(coordinates.size() / 3);
      std::vector<std::uint64_t> ids;
      std::string                item;
      while (line >> item)
      {
        const std::string index = item.substr(0, item.find('/'));
        char *            end = nullptr;
        errno = 0;
        const long long value = std::strtoll(index.c_str(), &end, 10);
        if (index.empty() || *end != '\0' || errno == ERANGE)
        {
          scan.Fail(Quote(item) + " is not a vertex index");
        }
        const long long id = value > 0 ? value - 1 : known + value;
        if (value == 0 || id < 0 || id >= known)
        {
          scan.Fail("vertex index " + index + " refers to no vertex (" + std::to_string(known) +
                    " vertices read so far)");
        }
        ids.push_back(static_cast<std::uint64_t>(id));
      }
      faces.push_back(ids);
      curves.push_back(kind == "l");
    }
  }
  MeshBuilder builder(path);
  builder.ReservePoints(coordinates.size() / 3);
  for (size_t i = 0; i < coordinates.size() / 3; ++i)
  {
    builder.SetPoint(i, coordinates[3 * i], coordinates[3 * i + 1], coordinates[3 * i + 2]);
  }
  for (size_t f = 0; f < faces.size(); ++f)
  {
    if (!faces[f].empty() && (curves[f] || faces[f].size() >= 3))
    {
      builder.AddCell(faces[f], curves[f]);
    }
  }
  return builder.GetMesh();
}

} // namespace

// --- Public functions --------------------------------------------------------

void
InstallSignalCleanup()
{
  sigemptyset(&g_HandledSignals);
  for (const int signalNumber : { SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE })
  {
    sigaddset(&g_HandledSignals, signalNumber);
  }
  pthread_sigmask(SIG_BLOCK, &g_HandledSignals, nullptr);
  std::thread(WatchSignals).detach();
}

int
RegisterTemporaryDirectory(const std::string & path, bool recursive)
{
  return RegisterCleanup(path, recursive);
}

void
UnregisterTemporaryDirectory(int id)
{
  UnregisterCleanup(id);
}

std::unique_lock<std::mutex>
LockTemporaryOutputs()
{
  return std::unique_lock<std::mutex>(g_CleanupMutex);
}

std::string
OneLine(const std::string & text)
{
  // Every line, joined: "ITK ERROR: MeshFileReader(0x5581...): message" ->
  // "message"; runs of spaces collapsed.
  std::string        joined;
  std::istringstream lines(text);
  std::string        line;
  const std::string  prefix = "ITK ERROR: ";
  while (std::getline(lines, line))
  {
    const auto object = line.find("): ");
    if ((line.compare(0, prefix.size(), prefix) == 0 || line.compare(0, 12, "itk::ERROR: ") == 0) &&
        object != std::string::npos)
    {
      line = line.substr(object + 3);
    }
    std::string collapsed;
    for (const char c : line)
    {
      const bool space = std::isspace(static_cast<unsigned char>(c)) != 0;
      if (space && (collapsed.empty() || collapsed.back() == ' '))
      {
        continue;
      }
      collapsed += space ? ' ' : c;
    }
    while (!collapsed.empty() && collapsed.back() == ' ')
    {
      collapsed.pop_back();
    }
    if (collapsed.empty())
    {
      continue;
    }
    if (!joined.empty())
    {
      joined += joined.back() == ':' || joined.back() == '.' ? " " : "; ";
    }
    joined += collapsed;
    if (joined.size() > 400)
    {
      joined = joined.substr(0, 397) + "...";
      break;
    }
  }
  while (!joined.empty() && (joined.back() == ':' || joined.back() == ' '))
  {
    joined.pop_back();
  }
  return joined.empty() ? std::string("unknown error") : joined;
}

AtomicOutput::AtomicOutput(const std::string & path)
  : m_Final(path)
{
  static std::atomic<unsigned int> counter{ 0 };
  const fs::path                   finalPath(path);
  const fs::path                   directory = finalPath.has_parent_path() ? finalPath.parent_path() : fs::path(".");
  // A short name, whatever the length of the output's: the temporary
  // directory stays within the file system's limit on names.
  const fs::path temporaryDirectory =
    directory / (".edmodel-" + std::to_string(getpid()) + "-" + std::to_string(counter++));
  std::error_code error;
  fs::remove_all(temporaryDirectory, error);
  if (!fs::create_directory(temporaryDirectory, error))
  {
    throw Error("cannot write " + Quote(path) + ": " + error.message());
  }
  m_Directory = temporaryDirectory.string();
  m_Slot = RegisterCleanup(m_Directory, true);
  // The extension in lower case, as ITK's and VTK's writers recognise it.
  const std::string name = finalPath.filename().string();
  const std::string extension = GetExtension(path);
  m_Temporary = (temporaryDirectory / (name.substr(0, name.size() - extension.size()) + extension)).string();
}

AtomicOutput::~AtomicOutput()
{
  std::error_code error;
  fs::remove_all(m_Directory, error);
  UnregisterCleanup(m_Slot);
}

std::string
AtomicOutput::GetTemporaryPath() const
{
  return m_Temporary;
}

void
AtomicOutput::Commit()
{
  VerifyWrittenFiles(m_Directory, m_Final);
  const fs::path              finalPath(m_Final);
  const fs::path              destination = finalPath.has_parent_path() ? finalPath.parent_path() : fs::path(".");
  std::lock_guard<std::mutex> lock(g_CleanupMutex);
  std::error_code             error;
  for (const auto & entry : fs::directory_iterator(m_Directory))
  {
    const fs::path target = entry.path() == fs::path(m_Temporary) ? finalPath : destination / entry.path().filename();
    fs::rename(entry.path(), target, error);
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

namespace
{
/** The ImageIO that reads \a path, its header read; Error when none does. */
itk::ImageIOBase::Pointer
OpenImage(const std::string & path)
{
  RequireRegularFile(path, "image");
  itk::ImageIOBase::Pointer io;
  {
    CapturedOutput captured;
    io = itk::ImageIOFactory::CreateImageIO(path.c_str(), itk::IOFileModeEnum::ReadMode);
  }
  if (io.IsNull())
  {
    throw Error("cannot read image " + Quote(path) + ": no ITK image reader recognises it (extension '" +
                GetExtension(path) + "')");
  }
  io->SetFileName(path);
  {
    CapturedOutput captured;
    try
    {
      io->ReadImageInformation();
    }
    catch (const itk::ExceptionObject & exception)
    {
      throw Error("cannot read image " + Quote(path) + ": " + Describe(exception, captured.Text()));
    }
  }
  return io;
}

std::vector<size_t>
ImageSize(const itk::ImageIOBase * io)
{
  std::vector<size_t> size;
  for (unsigned int d = 0; d < io->GetNumberOfDimensions(); ++d)
  {
    size.push_back(io->GetDimensions(d));
  }
  return size;
}

/** The voxels of an image whose header \a io has read and whose size was
 * checked, as float, after the checks of geometry, memory and data. */
template <typename TImage>
typename TImage::Pointer
ReadImagePixels(const std::string & path, itk::ImageIOBase * io, bool gradientVectorFlow)
{
  CheckImageGeometry(path, io);
  // The file's pixels, the float image, the force filter's float images and
  // field (and the diffusion's arrays with gradient vector flow).
  const double     filePixel = static_cast<double>(io->GetComponentSize() * io->GetNumberOfComponents());
  constexpr double dimension = TImage::ImageDimension;
  CheckMemoryForImage(
    path, ImageSize(io), filePixel + 4.0 + (40.0 + (gradientVectorFlow ? 40.0 : 0.0)) * dimension / 3.0);
  CheckImageData(path, io);

  typename TImage::Pointer image;
  if (io->GetComponentType() == itk::IOComponentEnum::DOUBLE && io->GetNumberOfComponents() == 1)
  {
    image = ReadDoubleImage<TImage>(path, io);
  }
  else
  {
    auto reader = itk::ImageFileReader<TImage>::New();
    reader->SetImageIO(io);
    reader->SetFileName(path);
    CapturedOutput captured;
    try
    {
      reader->Update();
    }
    catch (const itk::ExceptionObject & exception)
    {
      throw Error("cannot read image " + Quote(path) + ": " + Describe(exception, captured.Text()));
    }
    image = reader->GetOutput();
    image->DisconnectPipeline();
  }
  CheckFiniteVoxels(path, image.GetPointer());
  return image;
}
} // namespace

ImageType::Pointer
ReadImage(const std::string & path, bool gradientVectorFlow)
{
  std::error_code error;
  if (fs::is_directory(path, error))
  {
    return ReadDicomSeries(path);
  }
  itk::ImageIOBase::Pointer io = OpenImage(path);
  const std::vector<size_t> size = ImageSize(io);
  unsigned int              extent = 0; // dimensions of more than one voxel
  for (const auto n : size)
  {
    extent += n > 1 ? 1 : 0;
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
  return ReadImagePixels<ImageType>(path, io, gradientVectorFlow);
}

ImageInfo
ReadImageInfo(const std::string & path)
{
  ImageInfo       info;
  std::error_code error;
  if (fs::is_directory(path, error))
  {
    info.dimension = 3; // a DICOM series
    return info;
  }
  itk::ImageIOBase::Pointer io = OpenImage(path);
  info.size = ImageSize(io);
  info.description = DescribeSize(info.size);
  unsigned int extent = 0;
  for (const auto n : info.size)
  {
    extent += n > 1 ? 1 : 0;
  }
  info.dimension = extent <= 2 ? 2 : extent;
  return info;
}

Image2DType::Pointer
ReadImage2D(const std::string & path, bool gradientVectorFlow)
{
  itk::ImageIOBase::Pointer io = OpenImage(path);
  const std::vector<size_t> size = ImageSize(io);
  // A 2-D image, or a volume of one slice along its third axis (and any
  // later axes of one voxel): the reader keeps the first two axes.
  bool plane = size.size() >= 2 && size[0] >= 2 && size[1] >= 2;
  for (size_t d = 2; d < size.size(); ++d)
  {
    plane = plane && size[d] == 1;
  }
  if (!plane)
  {
    throw Error("image " + Quote(path) + " is " + DescribeSize(size) +
                ": a 2-D image needs at least 2 x 2 pixels, and a volume of one slice its slice across the third "
                "axis (N x M x 1)");
  }
  return ReadImagePixels<Image2DType>(path, io, gradientVectorFlow);
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
/** Every coordinate finite and within 1e12 of 0 (what is "mesh" or
 * "contour" in the message). */
void
CheckCoordinates(const MeshType * mesh, const char * what, const std::string & path, const std::string & option)
{
  for (auto it = mesh->GetPoints()->Begin(); it != mesh->GetPoints()->End(); ++it)
  {
    for (unsigned int k = 0; k < 3; ++k)
    {
      if (!(std::abs(it.Value()[k]) <= 1e12))
      {
        throw Error(option + ": " + what + " " + Quote(path) + " has point " + std::to_string(it.Index()) + " at " +
                    FormatNumber(it.Value()[0]) + ", " + FormatNumber(it.Value()[1]) + ", " +
                    FormatNumber(it.Value()[2]) + ": edmodel needs finite coordinates within 1e+12 of 0");
      }
    }
  }
}

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
  CheckCoordinates(mesh, "mesh", path, option);
  return mesh;
}
} // namespace

MeshType::Pointer
ReadMesh(const std::string & path, const std::string & option)
{
  RequireRegularFile(path, "mesh");
  const std::string extension = GetExtension(path);
  try
  {
    if (extension == ".vtk")
    {
      return CheckSurfaceMesh(ReadLegacyVTK(path), path, option);
    }
    if (extension == ".off")
    {
      return CheckSurfaceMesh(ReadOFF(path), path, option);
    }
    if (extension == ".obj")
    {
      return CheckSurfaceMesh(ReadOBJ(path), path, option);
    }
  }
  catch (const Error & error)
  {
    if (std::string(error.what()).compare(0, option.size(), option) == 0)
    {
      throw;
    }
    throw Error(option + ": " + error.what());
  }
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
      CapturedOutput captured;
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
  itk::MeshIOBase::Pointer io;
  {
    CapturedOutput captured;
    io = itk::MeshIOFactory::CreateMeshIO(path.c_str(), itk::IOFileModeEnum::ReadMode);
  }
  if (io.IsNull() || extension != ".gii")
  {
    throw Error(option + ": cannot read mesh " + Quote(path) + ": unknown mesh format (use " + MeshExtensionsText() +
                ")");
  }
  auto reader = itk::MeshFileReader<MeshType>::New();
  reader->SetMeshIO(io);
  reader->SetFileName(path);
  {
    CapturedOutput captured;
    try
    {
      reader->Update();
    }
    catch (const itk::ExceptionObject & exception)
    {
      throw Error(option + ": cannot read mesh " + Quote(path) + ": " + Describe(exception, captured.Text()));
    }
  }
  MeshType::Pointer mesh = reader->GetOutput();
  mesh->DisconnectPipeline();
  return CheckSurfaceMesh(mesh, path, option);
}

MeshType::Pointer
ReadCurveMesh(const std::string & path, const std::string & option)
{
  RequireRegularFile(path, "contour");
  const std::string extension = GetExtension(path);
  MeshType::Pointer mesh;
  try
  {
    if (extension == ".vtk")
    {
      mesh = ReadLegacyVTK(path);
    }
    else if (extension == ".vtp")
    {
      if (!HasVTK())
      {
        throw Error("reading .vtp needs VTK, and this edmodel was built without VTK (use .csv or .vtk)");
      }
      try
      {
        CapturedOutput captured;
        mesh = ReadPolyDataMesh(path);
      }
      catch (const itk::ExceptionObject & exception)
      {
        throw Error("cannot read contour " + Quote(path) + ": " + OneLine(exception.GetDescription()));
      }
    }
    else
    {
      throw Error("unknown contour extension '" + extension + "' in " + Quote(path) + " (use .csv, .vtk or .vtp)");
    }
  }
  catch (const Error & error)
  {
    if (std::string(error.what()).compare(0, option.size(), option) == 0)
    {
      throw;
    }
    throw Error(option + ": " + error.what());
  }
  CheckCoordinates(mesh, "contour", path, option);
  return mesh;
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
  if (!IsWritableImageExtension(GetExtension(path)))
  {
    throw Error(option + ": unknown image extension '" + GetExtension(path) + "' in " + Quote(path) +
                " (use .nii.gz, .nii, .nrrd, .nhdr, .mha or .mhd)");
  }
  CheckOutputDirectory(path, option);
}

void
CheckNotAnInput(const std::string & output, const std::string & option, const std::vector<std::string> & inputs)
{
  std::error_code error;
  const fs::path  target = fs::weakly_canonical(output, error);
  for (const auto & input : inputs)
  {
    if (input.empty())
    {
      continue;
    }
    std::error_code same;
    if (fs::equivalent(output, input, same) || (!error && target == fs::weakly_canonical(input, same)))
    {
      throw Error(option + ": " + Quote(output) + " is an input of this run (" + Quote(input) +
                  "): writing it would replace the input");
    }
  }
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
    catch (const Error & error)
    {
      throw Error("cannot write mesh " + Quote(path) + ": " + error.what());
    }
    output.Commit();
    return;
  }
  auto writer = itk::MeshFileWriter<MeshType>::New();
  writer->SetInput(mesh);
  writer->SetFileName(output.GetTemporaryPath());
  {
    CapturedOutput captured;
    try
    {
      writer->Update();
    }
    catch (const itk::ExceptionObject & exception)
    {
      throw Error("cannot write mesh " + Quote(path) + ": " + Describe(exception, captured.Text()));
    }
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
  {
    CapturedOutput captured;
    try
    {
      writer->Update();
    }
    catch (const itk::ExceptionObject & exception)
    {
      throw Error("cannot write image " + Quote(path) + ": " + Describe(exception, captured.Text()));
    }
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
  const std::string extension = GetExtension(path);
  if (extension == ".nii" || extension == ".nii.gz")
  {
    // NIfTI stores vectors, not covariant vectors: the same components.
    using VectorImageType = itk::Image<itk::Vector<float, 3>, 3>;
    auto vectors = VectorImageType::New();
    vectors->CopyInformation(image);
    vectors->SetRegions(image->GetBufferedRegion());
    vectors->Allocate();
    const auto *             in = image->GetBufferPointer();
    auto *                   out = vectors->GetBufferPointer();
    const itk::SizeValueType n = image->GetBufferedRegion().GetNumberOfPixels();
    for (itk::SizeValueType i = 0; i < n; ++i)
    {
      for (unsigned int k = 0; k < 3; ++k)
      {
        out[i][k] = in[i][k];
      }
    }
    WriteAnyImage(vectors.GetPointer(), path);
    return;
  }
  WriteAnyImage(image, path);
}

void
WriteImage(const Image2DType * image, const std::string & path)
{
  WriteAnyImage(image, path);
}

void
WriteImage(const Force2DType * image, const std::string & path)
{
  // ITK 5.2's NIfTI writer refuses this field (RunSegmentContour says so
  // before computing).
  WriteAnyImage(image, path);
}

void
WriteFileContents(const std::string & data, const std::string & path)
{
  WriteFileChecked(data, path, path);
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
