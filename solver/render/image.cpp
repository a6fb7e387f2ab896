#include "solver/render/image.h"

#include <png.h>

#include <stdexcept>

#include "solver/util/error.h"

namespace leaflux {

Image::Image(int width, int height, Rgb fill)
    : width_(width), height_(height), pixels_(static_cast<std::size_t>(width) * height, fill) {}

void Image::Paste(const Image& other, int x, int y) {
    for (int j = 0; j < other.Height(); ++j)
        for (int i = 0; i < other.Width(); ++i) Set(x + i, y + j, other.At(i, j));
}

namespace {

// libpng's simplified API (no setjmp, the error in png.message): `image` described for it.
png_image Described(const Image& image) {
    static_assert(sizeof(Rgb) == 3, "pixels are packed RGB");
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(image.Width());
    png.height = static_cast<png_uint_32>(image.Height());
    png.format = PNG_FORMAT_RGB;
    return png;
}

}  // namespace

void WritePng(const Image& image, const std::string& path) {
    png_image png = Described(image);
    const bool written =
        png_image_write_to_file(&png, path.c_str(), 0, &image.At(0, 0), 0, nullptr);
    const std::string message = png.message;
    png_image_free(&png);
    if (!written) throw InputError(ErrorCode::kIo, path, "cannot write the PNG: " + message);
}

std::string EncodePng(const Image& image) {
    png_image png = Described(image);
    // First the size (a null buffer), then the bytes.
    png_alloc_size_t bytes = 0;
    std::string out;
    bool written = png_image_write_to_memory(&png, nullptr, &bytes, 0, &image.At(0, 0), 0, nullptr);
    if (written) {
        out.resize(bytes);
        written =
            png_image_write_to_memory(&png, out.data(), &bytes, 0, &image.At(0, 0), 0, nullptr);
        out.resize(bytes);
    }
    const std::string message = png.message;
    png_image_free(&png);
    if (!written) throw std::runtime_error("cannot encode the PNG: " + message);
    return out;
}

Image ReadPng(const std::string& path) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&png, path.c_str()))
        throw InputError(ErrorCode::kIo, path, std::string("cannot read the PNG: ") + png.message);
    png.format = PNG_FORMAT_RGB;
    Image image(static_cast<int>(png.width), static_cast<int>(png.height));
    const bool read = png_image_finish_read(&png, nullptr, &image.At(0, 0), 0, nullptr);
    const std::string message = png.message;
    png_image_free(&png);
    if (!read) throw InputError(ErrorCode::kIo, path, "cannot read the PNG: " + message);
    return image;
}

}  // namespace leaflux
