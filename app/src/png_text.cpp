// PNG text chunks with libpng (see png_text.hpp).
//
// libpng reports errors by longjmp to the setjmp point: between that point and the last libpng call no
// object with a destructor lives in read_png_text's frame (the row buffer is libpng's own, freed by the
// clean-up), and the values are copied out only after libpng has finished.

#include "png_text.hpp"

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>

namespace hk::app {
namespace {

constexpr png_alloc_size_t kMaxChunkBytes = 1u << 20;  // a text chunk inflated beyond this is refused

void silent_warning(png_structp, png_const_charp) {}
void jump_on_error(png_structp png, png_const_charp) { png_longjmp(png, 1); }

/// Latin-1 (tEXt, zTXt) to UTF-8.
std::string latin1_to_utf8(const char* s, std::size_t n) {
  std::string out;
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      out.push_back(static_cast<char>(c));
    } else {
      out.push_back(static_cast<char>(0xC0 | (c >> 6)));
      out.push_back(static_cast<char>(0x80 | (c & 0x3F)));
    }
  }
  return out;
}

/// The file's text chunks after libpng read it whole; false when it could not.
bool read_chunks(std::FILE* f, png_structp png, png_infop info, png_bytep* row) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_init_io(png, f);
  png_set_chunk_malloc_max(png, kMaxChunkBytes);
  png_read_info(png, info);
  // The image data must be read to reach the chunks after it; one row at a time, into one buffer.
  const int passes = png_set_interlace_handling(png);
  png_read_update_info(png, info);
  const png_uint_32 height = png_get_image_height(png, info);
  *row = static_cast<png_bytep>(png_malloc(png, png_get_rowbytes(png, info)));
  for (int pass = 0; pass < passes; ++pass)
    for (png_uint_32 y = 0; y < height; ++y) png_read_row(png, *row, nullptr);
  png_read_end(png, info);
  return true;
}

}  // namespace

PngText read_png_text(const std::string& path) {
  PngText out;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return out;
  png_byte sig[8] = {};
  if (std::fread(sig, 1, 8, f) != 8 || png_sig_cmp(sig, 0, 8) != 0) {
    std::fclose(f);
    return out;
  }
  std::rewind(f);
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, jump_on_error, silent_warning);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  png_bytep row = nullptr;
  if (info != nullptr && read_chunks(f, png, info, &row)) {
    png_textp text = nullptr;
    int n = 0;
    png_get_text(png, info, &text, &n);
    bool have_title = false, have_description = false;
    for (int i = 0; i < n; ++i) {
      const bool title = std::strcmp(text[i].key, "Title") == 0, description = std::strcmp(text[i].key, "Description") == 0;
      if ((!title || have_title) && (!description || have_description)) continue;
      const bool utf8 = text[i].compression >= PNG_ITXT_COMPRESSION_NONE;  // iTXt
      const std::size_t len = utf8 ? text[i].itxt_length : text[i].text_length;
      std::string value = utf8 ? std::string(text[i].text, len) : latin1_to_utf8(text[i].text, len);
      (title ? out.title : out.description) = std::move(value);
      (title ? have_title : have_description) = true;
    }
  }
  if (row != nullptr) png_free(png, row);
  png_destroy_read_struct(png != nullptr ? &png : nullptr, info != nullptr ? &info : nullptr, nullptr);
  std::fclose(f);
  return out;
}

}  // namespace hk::app
