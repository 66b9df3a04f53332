// The .vti reader (vti_reader.hpp): VTK's XML image reader, its errors turned into one BadInput.
#include "vti_reader.hpp"

#include <orogen/error.hpp>
#include <orogen/io.hpp>

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkNew.h>
#include <vtkObject.h>
#include <vtkPointData.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkXMLImageDataReader.h>

#include <cmath>

namespace orogen::vti {

namespace {

struct Layout {
    Header header;
    bool north_up_rows = false;  ///< the second axis is Y (north): rows counted from the south
};

Layout layout_of(const int extent[6], const double spacing[3], const std::filesystem::path& path) {
    const int nx = extent[1] - extent[0] + 1, ny = extent[3] - extent[2] + 1, nz = extent[5] - extent[4] + 1;
    if (nx < 1 || ny < 1 || nz < 1) throw BadInput(path.string() + " holds an empty image; give a .vti with samples");
    Layout l;
    if (nz == 1) {
        l.header = {nx, ny, spacing[0]};
        l.north_up_rows = true;
    } else if (ny == 1) {
        l.header = {nx, nz, spacing[0]};
    } else {
        throw BadInput(path.string() + " is a " + std::to_string(nx) + "x" + std::to_string(ny) + "x" +
                       std::to_string(nz) + " volume, not one layer of heights; give a 2-D image (export:vtk's .vti)");
    }
    if (!(l.header.cell > 0.0) || !std::isfinite(l.header.cell)) l.header.cell = 0.0;  // the caller asks for one
    if (const std::string problem = heightmap_memory_problem(nx, l.header.height); !problem.empty())
        throw BadInput(path.string() + " is " + std::to_string(nx) + "x" + std::to_string(l.header.height) +
                       " samples and " + problem);
    return l;
}

Layout read_layout(vtkXMLImageDataReader* reader, const std::filesystem::path& path) {
    if (const std::string problem = regular_file_problem(path); !problem.empty())
        throw BadInput(path.string() + " " + problem);
    if (!reader->CanReadFile(path.c_str()))
        throw BadInput(path.string() + " is not a VTK XML image (.vti) VTK can read");
    reader->SetFileName(path.c_str());
    reader->UpdateInformation();
    int extent[6];
    reader->GetOutputInformation(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent);
    double spacing[3] = {1, 1, 1};
    if (reader->GetOutputInformation(0)->Has(vtkDataObject::SPACING()))
        reader->GetOutputInformation(0)->Get(vtkDataObject::SPACING(), spacing);
    return layout_of(extent, spacing, path);
}

}  // namespace

Header read_header(const std::filesystem::path& path) {
    vtkObject::GlobalWarningDisplayOff();
    vtkNew<vtkXMLImageDataReader> reader;
    return read_layout(reader, path).header;
}

std::shared_ptr<Heightmap> read(const std::filesystem::path& path, double cell) {
    vtkObject::GlobalWarningDisplayOff();
    vtkNew<vtkXMLImageDataReader> reader;
    const Layout l = read_layout(reader, path);
    reader->Update();
    vtkImageData* image = reader->GetOutput();
    vtkDataArray* heights = image ? image->GetPointData()->GetArray("height") : nullptr;
    if (!heights) {
        std::string names;
        if (image)
            for (int i = 0; i < image->GetPointData()->GetNumberOfArrays(); ++i) {
                const char* n = image->GetPointData()->GetArrayName(i);
                names += std::string(names.empty() ? "" : ", ") + (n ? n : "(unnamed)");
            }
        throw BadInput(path.string() + " has no point array 'height' (" +
                       (names.empty() ? std::string("it has no point arrays") : "its arrays: " + names) +
                       "); orogen reads the heights of export:vtk's .vti");
    }
    const auto w = std::size_t(l.header.width), h = std::size_t(l.header.height);
    if (heights->GetNumberOfComponents() != 1 || std::size_t(heights->GetNumberOfTuples()) != w * h)
        throw BadInput(path.string() + ": its 'height' array is not one number per sample; the file is damaged");
    if (!(cell > 0.0)) cell = l.header.cell;
    if (!(cell > 0.0))
        throw BadInput(path.string() +
                       " has no positive spacing along X to take the cell size from; give "
                       "cell=METRES (orogen analyze: --cell)");
    auto hm = std::make_shared<Heightmap>(l.header.width, l.header.height, cell);
    auto& out = hm->heights();
    for (std::size_t r = 0; r < h; ++r) {
        const std::size_t row = l.north_up_rows ? h - 1 - r : r;  // up=z counts rows from the south
        for (std::size_t x = 0; x < w; ++x) out[row * w + x] = float(heights->GetComponent(vtkIdType(r * w + x), 0));
    }
    return hm;
}

}  // namespace orogen::vti
