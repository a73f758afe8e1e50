#ifndef edmodelIO_h
#define edmodelIO_h

// Image and mesh files for edmodel: reading with one-line errors, and writing
// through a temporary directory so that a failed run leaves no partial file.

#include "itkCovariantVector.h"
#include "itkImage.h"
#include "itkMesh.h"

#include <mutex>
#include <string>
#include <vector>

namespace edm
{

using ImageType = itk::Image<float, 3>;
using ForceImageType = itk::Image<itk::CovariantVector<float, 3>, 3>;
/** Double coordinates: physical positions far from the origin keep their
 * precision. */
using MeshType = itk::Mesh<double, 3, itk::DefaultStaticMeshTraits<double, 3, 3, double, double>>;

/** Reads a 3-D image (a file ITK reads, or a directory holding a DICOM
 * series) as float. Throws Error (exit code 2) naming the problem, before
 * allocating the voxels where it can: missing, unreadable or not a regular
 * file (a FIFO), unknown format, a 2-D or 4-D image, spacing or origin out of
 * range, data shorter than the header announces (truncated MetaImage, NIfTI,
 * NRRD, DICOM slices; compressed data inflated to check), more memory needed
 * than available (with \a gradientVectorFlow, the diffusion's arrays too),
 * NaN or infinite voxels, double values beyond the float range. The
 * libraries' own messages are folded into the Error's line. */
ImageType::Pointer
ReadImage(const std::string & path, bool gradientVectorFlow = false);

/** 2-D images and contours (edmodelContour.cxx). */
using Image2DType = itk::Image<float, 2>;
using Force2DType = itk::Image<itk::CovariantVector<float, 2>, 2>;
using ContourMeshType = itk::Mesh<double, 2, itk::DefaultStaticMeshTraits<double, 2, 2, double, double, double>>;

/** What the header of an image file says, read without its voxels. */
struct ImageInfo
{
  /** 2 for a 2-D image or a volume of at most two axes longer than one voxel
   * (a single slice), otherwise the number of such axes; 3 for a DICOM
   * series directory. */
  unsigned int        dimension{ 3 };
  std::vector<size_t> size;
  std::string         description; // "32 x 32", "24 x 24 x 1"
};

/** Reads the header of \a path. Throws Error (exit code 2) when the file is
 * missing, not a regular file, or no ITK reader recognises it. */
ImageInfo
ReadImageInfo(const std::string & path);

/** Reads a 2-D image (PNG, TIFF, JPEG, BMP, 2-D NIfTI, NRRD, MetaImage), or
 * a volume of one slice across its third axis, as float, with the checks of
 * ReadImage. Throws Error (exit code 2). */
Image2DType::Pointer
ReadImage2D(const std::string & path, bool gradientVectorFlow = false);

/** Reads the points and cells of a curve file, .vtk (legacy POLYDATA) or
 * .vtp (with VTK): no triangle needed. Throws Error, its message starting
 * with \a option. */
MeshType::Pointer
ReadCurveMesh(const std::string & path, const std::string & option);

/** Reads a surface mesh (.vtk, .obj, .off, .gii; .vtp and .stl with VTK). \a option names the
 * command-line option in messages. Throws Error when the file is missing,
 * unreadable, of an unknown format or has no triangle or polygon. Legacy .vtk,
 * .off and .obj are parsed here, not by ITK 5.2's readers (which loop forever
 * on some malformed files): every count is checked against the file's size
 * before anything is allocated, every token as it is read (non-finite
 * coordinates, indices out of range); OBJ's negative indices count back. */
MeshType::Pointer
ReadMesh(const std::string & path, const std::string & option);

/** Number of triangles and polygons of a mesh. */
size_t
CountSurfaceCells(const MeshType * mesh);

/** Mesh files through VTK (.vtp, .stl), defined only when built with VTK. */
MeshType::Pointer
ReadPolyDataMesh(const std::string & path);
void
WritePolyDataMesh(const MeshType * mesh, const std::string & path);

/** Checks, before any computation, that \a path can take a mesh: a known
 * extension and an existing directory. Throws Error otherwise. */
void
CheckMeshOutputPath(const std::string & path, const std::string & option);

/** Same for an image: .nii.gz, .nii, .nrrd, .nhdr, .mha or .mhd. */
void
CheckImageOutputPath(const std::string & path, const std::string & option);

/** Throws Error when \a output names the same file as one of \a inputs. */
void
CheckNotAnInput(const std::string & output, const std::string & option, const std::vector<std::string> & inputs);

/** Blocks SIGINT, SIGTERM, SIGHUP, SIGQUIT and SIGPIPE in every thread
 * (call it first in main, before any thread starts) and starts the thread
 * that takes them: it removes the temporary outputs in progress, waits for a
 * Commit() under way, then lets the signal end the process. */
void
InstallSignalCleanup();

/** A directory the signal thread removes (recursively, or only when empty)
 * if a signal ends the run; the id unregisters it. */
int
RegisterTemporaryDirectory(const std::string & path, bool recursive);
void
UnregisterTemporaryDirectory(int id);
/** Held while files are written into a temporary directory registered for
 * cleanup: the signal thread takes it before it removes the temporary
 * outputs (and keeps it), so that no file appears in a directory it is
 * removing. */
std::unique_lock<std::mutex>
LockTemporaryOutputs();

/** Writes \a data to \a path, checking every write and the close (a full
 * disk is an Error). */
void
WriteFileContents(const std::string & data, const std::string & path);

/** Writers: the file appears complete, or not at all. Throw Error (exit
 * code 2) when writing fails. */
void
WriteMesh(const MeshType * mesh, const std::string & path);
void
WriteImage(const ImageType * image, const std::string & path);
void
WriteImage(const ForceImageType * image, const std::string & path);
void
WriteImage(const Image2DType * image, const std::string & path);
void
WriteImage(const Force2DType * image, const std::string & path);

/** A file written through a temporary directory beside it,
 * DIR/.edmodel-PID-K/NAME (same file system; a short directory name whatever
 * NAME's length; NAME with its extension in lower case so that writers pick
 * the format, and multi-file formats such as .mhd + .raw or a .pvd series
 * keep consistent names). Commit() checks that the files reached the disk and
 * that the file system did not fill up (some writers do not check their
 * writes), then renames them into DIR (NAME to the path given); otherwise the
 * destructor (or a signal, see InstallSignalCleanup) removes them: a failed
 * run leaves no partial output. */
class AtomicOutput
{
public:
  explicit AtomicOutput(const std::string & path);
  ~AtomicOutput();
  AtomicOutput(const AtomicOutput &) = delete;
  AtomicOutput &
  operator=(const AtomicOutput &) = delete;

  /** Where to write: DIR/.edmodel-PID-NAME/NAME. */
  std::string
  GetTemporaryPath() const;

  void
  Commit();

private:
  std::string m_Final;
  std::string m_Directory;
  std::string m_Temporary;
  int         m_Slot{ -1 };
};

/** Writes every K-th iteration of a deformation as .vtp files and a ParaView
 * .pvd collection DIRECTORY/NAME.pvd (needs VTK). The files appear when
 * Commit() succeeds. */
class SnapshotSeries
{
public:
  SnapshotSeries(const std::string & directory, const std::string & name);
  ~SnapshotSeries();
  SnapshotSeries(const SnapshotSeries &) = delete;
  SnapshotSeries &
  operator=(const SnapshotSeries &) = delete;

  void
  Add(const MeshType * mesh, itk::SizeValueType iteration);
  void
  Commit();
  std::string
  GetCollectionPath() const;
  unsigned int
  GetNumberOfFiles() const;

private:
  struct Internals;
  Internals * m_Internals;
};

/** The seed's Figure 1, written by edmodel demo: the mesh over the middle
 * slice of the image (across y) at iterations 0, 10, 50 and the last, in one
 * PNG rendered offscreen by edm::WriteFigurePNG (vtk/rendering). Needs a build
 * with VTK rendering (edmodelFigure.cxx). */
class FigureOne
{
public:
  FigureOne();
  ~FigureOne();
  FigureOne(const FigureOne &) = delete;
  FigureOne &
  operator=(const FigureOne &) = delete;

  /** Empty when the figure can be rendered here; otherwise why not (no VTK
   * rendering in this build, or no X display for a VTK that needs one). */
  static std::string
  WhyUnavailable();

  /** Keeps a copy of \a mesh when \a iteration is one the figure shows. */
  void
  Add(const MeshType * mesh, itk::SizeValueType iteration);

  /** Writes the figure of the meshes kept and \a last to \a path, through
   * AtomicOutput. Throws Error when it cannot be rendered or written. */
  void
  Write(const ImageType * image, const MeshType * last, itk::SizeValueType lastIteration, const std::string & path);

private:
  struct Internals;
  Internals * m_Internals;
};

/** "a.b.c" -> ".c", "a.nii.gz" -> ".nii.gz", lower case. */
std::string
GetExtension(const std::string & path);

/** The first line of an exception's description, without trailing spaces. */
std::string
OneLine(const std::string & text);

} // namespace edm

#endif
