// An 8-bit RGB picture and its PNG file (written by libpng).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace leaflux {

struct Rgb {
    std::uint8_t r = 0, g = 0, b = 0;
    bool operator==(const Rgb&) const = default;
};

class Image {
  public:
    Image() : Image(0, 0) {}
    Image(int width, int height, Rgb fill = {});
    int Width() const { return width_; }
    int Height() const { return height_; }
    Rgb& At(int x, int y) { return pixels_[static_cast<std::size_t>(y) * width_ + x]; }
    const Rgb& At(int x, int y) const { return pixels_[static_cast<std::size_t>(y) * width_ + x]; }
    // Sets a pixel, ignoring those outside the picture (text and marks near its edge).
    void Set(int x, int y, Rgb colour) {
        if (x >= 0 && y >= 0 && x < width_ && y < height_) At(x, y) = colour;
    }
    // `other` placed with its top-left corner at (x, y).
    void Paste(const Image& other, int x, int y);

  private:
    int width_, height_;
    std::vector<Rgb> pixels_;
};

// Writes `image` as a PNG file; an InputError (kIo) naming the path when it cannot.
void WritePng(const Image& image, const std::string& path);
// The PNG file's bytes, for a picture sent rather than written.
std::string EncodePng(const Image& image);
// Reads a PNG file written by WritePng (or any PNG, converted to 8-bit RGB).
Image ReadPng(const std::string& path);

}  // namespace leaflux
