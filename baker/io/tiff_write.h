// write_image (image_io.h) for .tif and .tiff without OpenImageIO: baseline TIFF 6.0 (Adobe TIFF 6.0
// specification; the floating-point predictor from Adobe Photoshop TIFF Technical Note 3), strips of
// 32 rows, each compressed with Deflate (zlib, level 6) on its own, on every thread.
//
// OpenImageIO compressed a TIFF's strips on its own pool only when that pool had 2 or more workers
// besides the caller, so on 2 threads a 4096^2 16-bit map's write was 2.3-2.4 s of one core, longer
// than the rest of the bake (now 1.5 s on 2 threads); and every TIFF write loaded its ~260 libraries
// (0.3 s, 140 MB of peak memory). The tags are those it wrote, of the same types and values
// (little-endian; RGB, or grey, with unassociated alpha as an extra sample; uint 8 or 16 with the
// horizontal predictor, float 32 with the floating-point predictor; the metadata in the description
// tag as "key=value" items, the known text tags as tags), and the strips are the same bytes; only
// where the tags' values sit differs. DateTime is written only when given or SOURCE_DATE_EPOCH is
// set (OpenImageIO wrote the time of the write). Internal to io/.
#pragma once

#include <string>

#include "core/image.h"
#include "io/image_io.h"

namespace nmbake {

// Writes `image` as image_io.h's write_image does, `bits` (8, 16 or 32) as check_write gave them.
// False, with nothing written, for what a classic TIFF cannot hold (more than 4 channels, a file
// over 4 GiB): the caller writes it through OpenImageIO (BigTIFF). Throws as write_image does.
bool write_tiff_image(const std::string& path, const Image& image, const WriteOptions& options, int bits);

}  // namespace nmbake
