// Reading MAT files: v5/v7 through matio after a structural check of every variable against the
// bytes the file holds, v7.3 through HDF5 directly (see mat_file.hpp for the bounds).
#include <hdf5.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>

#include "isolated.hpp"
#include "mat_file.hpp"
#include "mapped_file.hpp"
#include "piezobench/core/error.hpp"
#include "piezobench/core/text.hpp"

namespace piezobench::io::detail {
namespace fs = std::filesystem;

namespace {

std::string bytes_text(unsigned long long n) { return std::to_string(n) + (n == 1 ? " byte" : " bytes"); }

// "500x1"
template <typename T>
std::string shape_text(const std::vector<T>& dims) {
  std::string out;
  for (size_t i = 0; i < dims.size(); ++i) {
    if (i > 0) out += 'x';
    out += std::to_string(dims[i]);
  }
  return out;
}

// ---- v5/v7: structural check ----------------------------------------------------------------

// The bytes of one top-level data element: the file itself, or the inflated stream of a
// miCOMPRESSED element. Both count what they have delivered (position()).
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  // Exactly n bytes into out (nullptr: skip them); false when the element ends first.
  virtual bool read(void* out, unsigned long long n) = 0;
  [[nodiscard]] unsigned long long position() const { return pos_; }

 protected:
  unsigned long long pos_ = 0;
};

class FileSource final : public ByteSource {
 public:
  FileSource(std::ifstream& in, unsigned long long start, unsigned long long size) : in_(in), start_(start), size_(size) {}
  bool read(void* out, unsigned long long n) override {
    if (n > size_ - pos_) return false;
    if (out != nullptr) {
      in_.clear();
      in_.seekg(static_cast<std::streamoff>(start_ + pos_));
      in_.read(static_cast<char*>(out), static_cast<std::streamsize>(n));
      if (static_cast<unsigned long long>(in_.gcount()) != n) return false;
    }
    pos_ += n;
    return true;
  }

 private:
  std::ifstream& in_;
  unsigned long long start_, size_;
};

// Inflates a miCOMPRESSED element on demand; never produces more than `limit` bytes.
class InflateSource final : public ByteSource {
 public:
  InflateSource(std::ifstream& in, unsigned long long start, unsigned long long size, unsigned long long limit)
      : in_(in), next_(start), left_(size), limit_(limit) {
    if (inflateInit(&z_) != Z_OK) failed_ = true;
    ready_ = !failed_;
  }
  ~InflateSource() override {
    if (ready_) inflateEnd(&z_);
  }
  InflateSource(const InflateSource&) = delete;
  InflateSource& operator=(const InflateSource&) = delete;

  bool read(void* out, unsigned long long n) override {
    if (failed_ || n > limit_ - std::min(limit_, pos_)) return (exceeded_ = n > limit_ - std::min(limit_, pos_), false);
    auto* dst = static_cast<unsigned char*>(out);
    while (n > 0) {
      const unsigned long long piece = std::min<unsigned long long>(n, out != nullptr ? n : scratch_.size());
      const unsigned chunk = static_cast<unsigned>(std::min<unsigned long long>(piece, 1u << 30));
      z_.next_out = out != nullptr ? dst : scratch_.data();
      z_.avail_out = chunk;
      while (z_.avail_out > 0) {
        if (z_.avail_in == 0) {
          if (left_ == 0) return false;
          const auto take = static_cast<std::streamsize>(std::min<unsigned long long>(left_, input_.size()));
          in_.clear();
          in_.seekg(static_cast<std::streamoff>(next_));
          in_.read(reinterpret_cast<char*>(input_.data()), take);
          if (in_.gcount() != take) return false;
          next_ += static_cast<unsigned long long>(take);
          left_ -= static_cast<unsigned long long>(take);
          z_.next_in = input_.data();
          z_.avail_in = static_cast<unsigned>(take);
        }
        const int rc = ::inflate(&z_, Z_NO_FLUSH);
        if (rc == Z_STREAM_END && z_.avail_out > 0) return false;
        if (rc != Z_OK && rc != Z_STREAM_END) return (failed_ = true, false);
      }
      pos_ += chunk;
      n -= chunk;
      if (out != nullptr) dst += chunk;
    }
    return true;
  }
  [[nodiscard]] bool exceeded() const { return exceeded_; }
  [[nodiscard]] bool corrupt() const { return failed_; }

 private:
  std::ifstream& in_;
  unsigned long long next_, left_, limit_;
  z_stream z_{};
  std::vector<unsigned char> input_ = std::vector<unsigned char>(1 << 16);
  std::vector<unsigned char> scratch_ = std::vector<unsigned char>(1 << 16);
  bool failed_ = false, ready_ = false, exceeded_ = false;
};

// v5 data types and classes (MAT-file format, tables 1-2 and 1-3): the one place a v5 file is parsed
// (checked, listed and, for a plain file, read).
int element_size(std::uint32_t type) {
  switch (type) {
    case 1: case 2: case 16: return 1;     // int8, uint8, utf8
    case 3: case 4: case 17: return 2;     // int16, uint16, utf16
    case 5: case 6: case 7: case 18: return 4;  // int32, uint32, single, utf32
    case 9: case 12: case 13: return 8;    // double, int64, uint64
    default: return 0;
  }
}

// A top-level variable of a v5 file: its header, where its element lies (uncompressed: what the own
// reader decodes), and where its data lie when it is a real double array stored as doubles in the
// file's own bytes (uncompressed, native byte order): what map_double_vector may use in place.
struct V5Variable {
  std::string name;
  matio_classes class_type = MAT_C_EMPTY;
  bool is_complex = false;
  std::vector<size_t> dims;
  unsigned long long element = 0, bytes = 0;  // file offset and size of the element's contents (0: compressed)
  unsigned long long offset = 0;              // file offset of the first double
  unsigned long long count = 0;               // its number of doubles (0: not a plain double array)
};

struct Tag {
  std::uint32_t type = 0;
  unsigned long long bytes = 0;
  bool small = false;
  unsigned char payload[4] = {};  // the data of a small element
};

// Walks one variable (a miMATRIX element, recursively) and refuses any declared size that the
// bytes present cannot back, before anything is allocated for it. Given a MatValue, the same walk
// also reads the variable into it (native byte order only: the own reader's files).
class V5Checker {
 public:
  // `base`: the file offset of the source's first byte when it reads the file itself (lets
  // plain() locate data); kNotInFile for an inflated stream.
  static constexpr unsigned long long kNotInFile = ~0ull;
  V5Checker(ByteSource& src, bool swap, std::string source, unsigned long long base = kNotInFile)
      : src_(src), swap_(swap), source_(std::move(source)), base_(base) {}

  // After the check of a top-level variable: its header, and where its data lie when it is a real
  // double array stored as doubles in the file's own bytes (see V5Variable).
  [[nodiscard]] const V5Variable& plain() const { return plain_; }

  // The whole element: tag (miMATRIX) then its contents.
  void check_element(const std::string& path) {
    const Tag tag = read_tag(path);
    if (tag.small || tag.type != kMiMatrix) fail(path, "a matrix element (type 14)", "type " + std::to_string(tag.type));
    check_matrix(tag.bytes, 0, path);
  }

  // Contents of a miMATRIX element of `bytes` bytes, starting at the source's position; read into
  // `out` when given.
  void check_matrix(unsigned long long bytes, int depth, std::string path, MatValue* out = nullptr) {
    if (depth > 32) fail(path, "structs or cells nested at most 32 deep", "deeper nesting");
    if (out != nullptr && swap_) fail(path, "a file in this machine's byte order", "the other one");
    if (bytes == 0) {  // an empty cell element
      if (out != nullptr) *out = MatValue("", MAT_C_EMPTY, {0, 0});
      return;
    }
    const unsigned long long end = src_.position() + bytes;
    const std::uint32_t flag_word = read_array_flags(path);
    const unsigned cls = flag_word & 0xffu;
    const bool complex = (flag_word & 0x800u) != 0;
    unsigned long long count = 1;
    const std::vector<std::uint32_t> dims = read_dimensions(path, count);
    const std::string shape = shape_text(dims);
    const matio_classes class_type = cls <= 17 ? static_cast<matio_classes>(cls) : MAT_C_EMPTY;
    const std::string name = read_name(path);
    if (depth == 0) {
      plain_.name = name;
      plain_.class_type = class_type;
      plain_.is_complex = complex;
      plain_.dims.assign(dims.begin(), dims.end());
    }
    if (out != nullptr) {
      *out = MatValue(name, class_type, std::vector<size_t>(dims.begin(), dims.end()), complex, (flag_word & 0x200u) != 0);
    }
    if (depth == 0 && !name.empty()) path = text::quote(name);
    const std::string what = path + " (declared " + shape + ")";

    if (cls == 1) {  // cell: one matrix element per cell
      check_children(count, end, depth, path, what, out);
    } else if (cls == 2) {
      check_struct(count, end, depth, path, what, out);
    } else if (cls == 4 || (cls >= 6 && cls <= 15)) {  // char and numeric classes
      const Tag real = check_data(count, end, path + " (real part)", what, out, false);
      constexpr unsigned kDoubleClass = 6, kLogicalFlag = 0x200u;
      if (depth == 0 && base_ != kNotInFile && !swap_ && cls == kDoubleClass && !complex && (flag_word & kLogicalFlag) == 0 &&
          real.type == kMiDouble && !real.small && count > 0 && real.bytes == count * 8) {
        plain_.offset = base_ + data_position_;
        plain_.count = count;
      }
      if (complex) check_data(count, end, path + " (imaginary part)", what, out, true);
    } else if (out != nullptr) {
      out->has_data = false;
    }
    // Anything else (sparse, object, function, opaque) is never read by piezobench: skipped.
    if (src_.position() > end) fail(path, "sub-elements inside the variable's " + bytes_text(bytes), "more");
    skip(end - src_.position(), path);
  }

 private:
  // The array flags sub-element: class in the low byte, 0x800 complex, 0x200 logical.
  std::uint32_t read_array_flags(const std::string& path) {
    const Tag flags = read_tag(path + " (array flags)");
    std::uint32_t flag_word = 0;
    if (flags.small) {
      std::memcpy(&flag_word, flags.payload, 4);
    } else {
      if (flags.bytes < 8) fail(path + " (array flags)", "8 bytes", bytes_text(flags.bytes));
      unsigned char raw[8];
      need(raw, 8, path + " (array flags)");
      std::memcpy(&flag_word, raw, 4);
      skip(padded(flags.bytes) - 8, path);
    }
    return fix(flag_word);
  }

  // The dimensions sub-element (1 to 32 of them); `count` gets their product, capped at 2^50.
  std::vector<std::uint32_t> read_dimensions(const std::string& path, unsigned long long& count) {
    const Tag dims_tag = read_tag(path + " (dimensions)");
    const unsigned long long rank = dims_tag.bytes / 4;
    if (dims_tag.bytes % 4 != 0 || rank < 1 || rank > 32) {
      fail(path + " (dimensions)", "1 to 32 dimensions of 4 bytes", bytes_text(dims_tag.bytes));
    }
    std::array<unsigned char, 128> dim_bytes{};
    read_payload(dims_tag, dim_bytes.data(), path + " (dimensions)");
    std::vector<std::uint32_t> dims;
    for (unsigned long long i = 0; i < rank; ++i) {
      std::uint32_t d;
      std::memcpy(&d, dim_bytes.data() + 4 * i, 4);
      d = fix(d);
      dims.push_back(d);
      count = d == 0 || count == 0 ? 0 : (count > (1ull << 50) / d ? (1ull << 50) : count * d);
    }
    return dims;
  }

  // The array name sub-element ("" when it is longer than 256 bytes: skipped).
  std::string read_name(const std::string& path) {
    const Tag name_tag = read_tag(path + " (name)");
    std::string name;
    if (name_tag.small) {
      name.assign(reinterpret_cast<const char*>(name_tag.payload), name_tag.bytes);
    } else if (name_tag.bytes <= 256) {
      name.resize(name_tag.bytes);
      need(name.data(), name_tag.bytes, path + " (name)");
      skip(padded(name_tag.bytes) - name_tag.bytes, path + " (name)");
    } else {
      skip(padded(name_tag.bytes), path + " (name)");
    }
    return name;
  }

  // A struct: field name length, names, then fields x elements.
  void check_struct(unsigned long long count, unsigned long long end, int depth, const std::string& path, const std::string& what,
                    MatValue* out) {
    const Tag len_tag = read_tag(path + " (field name length)");
    std::uint32_t len = 0;
    if (len_tag.small) {
      std::memcpy(&len, len_tag.payload, 4);
    } else {
      unsigned char raw[8] = {};
      if (len_tag.bytes < 4) fail(path + " (field name length)", "4 bytes", bytes_text(len_tag.bytes));
      need(raw, 4, path);
      skip(padded(len_tag.bytes) - 4, path);
      std::memcpy(&len, raw, 4);
    }
    len = fix(len);
    const Tag names_tag = read_tag(path + " (field names)");
    const unsigned long long fields = len == 0 ? 0 : names_tag.bytes / len;
    if (out != nullptr) {
      const unsigned long long left = end - std::min(end, src_.position());
      if (!names_tag.small && names_tag.bytes > left) {
        fail(path + " (field names)", "names inside the variable", bytes_text(names_tag.bytes) + " declared, " + bytes_text(left) + " left");
      }
      std::string names(std::max<unsigned long long>(names_tag.bytes, 4), '\0');  // a small element copies 4 bytes
      read_payload(names_tag, reinterpret_cast<unsigned char*>(names.data()), path + " (field names)");
      for (unsigned long long f = 0; f < fields; ++f) {
        const std::string_view field(names.data() + f * len, len);
        out->field_names.emplace_back(field.substr(0, std::min(field.size(), field.find('\0'))));
      }
    } else if (!names_tag.small) {
      skip(padded(names_tag.bytes), path + " (field names)");
    }
    const unsigned long long children = fields == 0 || count == 0 ? 0 : (count > (1ull << 50) / fields ? (1ull << 50) : count * fields);
    check_children(children, end, depth, path, what, out);
    if (out != nullptr) {
      for (size_t i = 0; i < out->items.size(); ++i) out->items[i].name = out->field_names[i % out->field_names.size()];
    }
  }

  void check_children(unsigned long long n, unsigned long long end, int depth, const std::string& path, const std::string& what,
                      MatValue* out) {
    // Each child is at least an 8-byte tag.
    if (n > (end - std::min(end, src_.position())) / 8) {
      fail(what, std::to_string(n) + " elements (8 bytes each at least)",
           bytes_text(end - std::min(end, src_.position())) + " in the variable");
    }
    for (unsigned long long i = 0; i < n; ++i) {
      const std::string child = path + "{" + std::to_string(i + 1) + "}";
      const Tag tag = read_tag(child);
      if (tag.small || tag.type != kMiMatrix) fail(child, "a matrix element (type 14)", "type " + std::to_string(tag.type));
      if (tag.bytes > end - std::min(end, src_.position())) {
        fail(child, "a size inside its parent", bytes_text(tag.bytes) + " declared, " +
                                                   bytes_text(end - std::min(end, src_.position())) + " left");
      }
      if (out != nullptr) out->items.emplace_back();
      check_matrix(tag.bytes, depth + 1, child, out != nullptr ? &out->items.back() : nullptr);
    }
  }

  // Checks one data element and returns its tag (data_position_: where its data start); reads its
  // first `count` values into `out` (the imaginary part when `imaginary`) when given.
  Tag check_data(unsigned long long count, unsigned long long end, const std::string& field, const std::string& what, MatValue* out,
                 bool imaginary) {
    const Tag tag = read_tag(field);
    data_position_ = src_.position();
    const int size = element_size(tag.type);
    if (size == 0) fail(field, "a numeric or character data type", "type " + std::to_string(tag.type));
    const unsigned long long left = end - std::min(end, src_.position());
    if (!tag.small && tag.bytes > left) fail(field, "data inside the variable", bytes_text(tag.bytes) + " declared, " + bytes_text(left) + " left");
    if (tag.bytes / static_cast<unsigned long long>(size) < count) {
      fail(what, std::to_string(count) + " elements of " + bytes_text(static_cast<unsigned long long>(size)),
           bytes_text(tag.bytes) + " of data");
    }
    if (out != nullptr) {
      read_values(tag, count, field, *out, imaginary);
    } else if (!tag.small) {
      skip(padded(tag.bytes), field);
    }
    return tag;
  }

  // The data of a checked element (at least `count` values) into `out`, and past its padding.
  void read_values(const Tag& tag, unsigned long long count, const std::string& field, MatValue& out, bool imaginary) {
    const auto size = static_cast<unsigned long long>(element_size(tag.type));
    std::vector<double>& values = imaginary ? out.im : out.re;
    if (tag.type == kMiDouble && out.class_type != MAT_C_CHAR && !tag.small) {
      values.resize(count);  // doubles: straight into place
      need(values.data(), count * 8, field);
    } else {
      // Characters in 8-bit units are UTF-8: all the element's bytes (the dimensions count
      // characters), else `count` values.
      const bool utf8 = out.class_type == MAT_C_CHAR && size == 1;
      const unsigned long long take = utf8 ? tag.bytes : count * size;
      std::vector<unsigned char> raw;
      const unsigned char* bytes = tag.payload;  // a small element holds at most 4 bytes
      if (!tag.small) {
        raw.resize(take);
        need(raw.data(), raw.size(), field);
        bytes = raw.data();
      }
      if (utf8) {
        out.text.assign(reinterpret_cast<const char*>(bytes), take);
        if (!tag.small) skip(padded(tag.bytes) - take, field);
        return;
      }
      values.resize(count);
      if (!numbers_to_doubles(tag.type, bytes, count, values.data())) fail(field, "numbers or characters", "type " + std::to_string(tag.type));
      if (out.class_type == MAT_C_CHAR) {
        out.text = utf8_from_units(values.data(), values.size());  // UTF-16/32 code units
        values.clear();
      }
    }
    if (!tag.small) skip(padded(tag.bytes) - count * size, field);
  }

  Tag read_tag(const std::string& where) {
    unsigned char raw[8];
    need(raw, 8, where);
    std::uint32_t a, b;
    std::memcpy(&a, raw, 4);
    std::memcpy(&b, raw + 4, 4);
    a = fix(a);
    b = fix(b);
    Tag t;
    if ((a >> 16) != 0) {  // small data element: byte count and type share the first word
      t.small = true;
      t.bytes = a >> 16;
      t.type = a & 0xffffu;
      if (t.bytes > 4) fail(where, "a small element of at most 4 bytes", bytes_text(t.bytes));
      std::memcpy(t.payload, raw + 4, 4);
    } else {
      t.type = a;
      t.bytes = b;
    }
    return t;
  }

  void read_payload(const Tag& tag, unsigned char* out, const std::string& where) {
    if (tag.small) {
      std::memcpy(out, tag.payload, 4);
      return;
    }
    need(out, tag.bytes, where);
    skip(padded(tag.bytes) - tag.bytes, where);
  }

  static unsigned long long padded(unsigned long long n) { return (n + 7) / 8 * 8; }
  std::uint32_t fix(std::uint32_t v) const {
    return swap_ ? ((v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24)) : v;
  }
  void need(void* out, unsigned long long n, const std::string& where) {
    if (!src_.read(out, n)) truncated(where, n);
  }
  void skip(unsigned long long n, const std::string& where) {
    if (n > 0 && !src_.read(nullptr, n)) truncated(where, n);
  }
  [[noreturn]] void truncated(const std::string& where, unsigned long long n) {
    if (const auto* z = dynamic_cast<const InflateSource*>(&src_); z != nullptr && z->exceeded()) {
      fail(where, "at most " + std::to_string(static_cast<long long>(kMaxInflation)) + " times the compressed size once inflated",
           "more (a compression bomb or a corrupt size)");
    }
    if (const auto* z = dynamic_cast<const InflateSource*>(&src_); z != nullptr && z->corrupt()) {
      fail(where, "a valid zlib stream", "corrupt compressed data");
    }
    fail(where, bytes_text(n) + " more in the variable", "the end of the variable (truncated or corrupt)");
  }
  [[noreturn]] void fail(const std::string& where, const std::string& expected, const std::string& found) {
    throw InputError(source_, "variable " + where, expected, found);
  }

  ByteSource& src_;
  bool swap_;
  std::string source_;
  unsigned long long base_;
  unsigned long long data_position_ = 0;
  V5Variable plain_;
};

// The first bytes decide whether the file is a MAT file at all: a v5/v7 file has a 128-byte
// header with the version 0x0100 and an endian indicator "IM"/"MI" at bytes 126..127; a v7.3 file
// is an HDF5 file with the same 128-byte MATLAB header in its user block (or a bare HDF5 file).
// Anything else (a CSV renamed .mat, a truncated header) is rejected here with a clear message.
// For v5, every top-level element is then checked against the file (see V5Checker): matio stops
// at the first variable it cannot read and reports the ones before it as if the file ended there,
// and allocates what a variable's header declares.
// Returns true for a v7.3 (HDF5) file. For v5, `vars` receives the top-level variables in file
// order (for a name given twice, the first is the one matio reads) and `own` whether the own reader
// reads the file: this machine's byte order, and every top-level element an uncompressed matrix.
bool check_mat_file(const fs::path& file, std::vector<V5Variable>& vars, bool& own) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "file", "a readable file", "cannot open it");
  char header[128] = {};
  in.read(header, sizeof header);
  const std::streamsize got = in.gcount();
  static const char kHdf5[8] = {'\x89', 'H', 'D', 'F', '\r', '\n', '\x1a', '\n'};
  if (got >= 8 && std::memcmp(header, kHdf5, 8) == 0) return true;
  if (got < 128) {
    throw InputError(file.string(), "file", "a MAT file (128-byte header)", std::to_string(got) + " bytes in total");
  }
  const bool little = header[126] == 'I' && header[127] == 'M';
  const bool big = header[126] == 'M' && header[127] == 'I';
  if (!little && !big) {
    throw InputError(file.string(), "file", "a MAT file (v5, v7 or v7.3)",
                     "no MATLAB header (bytes 126-127 are " + text::quote(std::string_view(header + 126, 2)) + ")");
  }
  // Version 0x0200 is v7.3: an HDF5 file (at byte 512).
  const auto version = static_cast<unsigned>(
      little ? (static_cast<unsigned char>(header[124]) | (static_cast<unsigned char>(header[125]) << 8))
             : ((static_cast<unsigned char>(header[124]) << 8) | static_cast<unsigned char>(header[125])));
  if (version == 0x0200) return true;
  in.seekg(0, std::ios::end);
  const auto size = static_cast<unsigned long long>(in.tellg());
  const bool swap = (little != (std::endian::native == std::endian::little));
  own = !swap;
  const auto u32 = [&](const unsigned char* p) {
    std::uint32_t v;
    std::memcpy(&v, p, 4);
    return swap ? ((v >> 24) | ((v >> 8) & 0xff00u) | ((v << 8) & 0xff0000u) | (v << 24)) : v;
  };
  unsigned long long pos = 128;
  int index = 0;
  while (pos < size) {
    ++index;
    if (pos + 8 > size) {
      throw InputError(file.string(), "file", "complete variables",
                       "a truncated file (variable " + std::to_string(index) + " at byte " + std::to_string(pos) + " has no complete tag)");
    }
    unsigned char tag[8];
    in.clear();
    in.seekg(static_cast<std::streamoff>(pos));
    in.read(reinterpret_cast<char*>(tag), 8);
    const std::uint32_t type = u32(tag);
    if ((type >> 16) != 0) {  // small data element: type and size share the first 4 bytes
      own = false;
      pos += 8;
      continue;
    }
    const unsigned long long nbytes = u32(tag + 4);
    unsigned long long next = pos + 8 + nbytes;
    if (type != kMiCompressed) next = (next + 7) / 8 * 8;  // miCOMPRESSED elements are not padded
    if (pos + 8 + nbytes > size) {
      throw InputError(file.string(), "file", "complete variables",
                       "a truncated file (variable " + std::to_string(index) + " at byte " + std::to_string(pos) + " declares " +
                           std::to_string(nbytes) + " bytes, " + std::to_string(size - pos - 8) + " are left)");
    }
    if (type == kMiMatrix) {
      FileSource src(in, pos + 8, nbytes);
      V5Checker check(src, swap, file.string(), pos + 8);
      check.check_matrix(nbytes, 0, std::to_string(index) + " (at byte " + std::to_string(pos) + ")");
      vars.push_back(check.plain());
      vars.back().element = pos + 8;
      vars.back().bytes = nbytes;
    } else if (type == kMiCompressed) {
      own = false;
      const auto limit = static_cast<unsigned long long>(kMaxInflation * static_cast<double>(nbytes)) + 4096;
      InflateSource src(in, pos + 8, nbytes, limit);
      V5Checker check(src, swap, file.string());
      check.check_element(std::to_string(index) + " (compressed, at byte " + std::to_string(pos) + ")");
      vars.push_back(check.plain());
    } else {
      own = false;
    }
    pos = next;
  }
  return false;
}

// ---- v5/v7: the own reader (plain files) or matio ---------------------------------------------

class Mat5Input final : public MatInput {
 public:
  // `mat`: matio's handle, or null when the own reader reads the file.
  Mat5Input(fs::path file, MatioPtr mat, std::vector<V5Variable> vars)
      : MatInput(std::move(file)), mat_(std::move(mat)), vars_(std::move(vars)) {}
  [[nodiscard]] bool v73() const override { return false; }
  [[nodiscard]] mat_t* mat() const { return mat_.get(); }
  [[nodiscard]] const std::vector<V5Variable>& vars() const { return vars_; }
  // The first variable of that name, or null.
  [[nodiscard]] const V5Variable* find(const std::string& name) const {
    const auto it = std::find_if(vars_.begin(), vars_.end(), [&](const V5Variable& v) { return v.name == name; });
    return it == vars_.end() ? nullptr : &*it;
  }
  // The bytes [offset, offset + n) of the file into out; InputError when they cannot be read.
  void read_at(unsigned long long offset, void* out, unsigned long long n) const {
    if (!in_.is_open()) in_.open(file(), std::ios::binary);
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(offset));
    in_.read(static_cast<char*>(out), static_cast<std::streamsize>(n));
    if (!in_ || static_cast<unsigned long long>(in_.gcount()) != n) {
      throw InputError(file().string(), "file", "the bytes checked when it was opened", "a read error (the file changed?)");
    }
  }
  // A variable read by the own reader (the walk that checked it, this time reading its data).
  [[nodiscard]] MatValue decode(const V5Variable& v) const {
    if (!in_.is_open()) in_.open(file(), std::ios::binary);
    FileSource src(in_, v.element, v.bytes);
    V5Checker walk(src, false, file().string(), v.element);
    MatValue out;
    walk.check_matrix(v.bytes, 0, text::quote(v.name), &out);
    return out;
  }
  // The file mapped once, on first use (nullptr when it cannot be mapped).
  [[nodiscard]] const std::shared_ptr<const MappedFile>& mapping() const {
    if (!mapped_) {
      mapping_ = MappedFile::open(file());
      mapped_ = true;
    }
    return mapping_;
  }

 private:
  MatioPtr mat_;
  std::vector<V5Variable> vars_;
  mutable std::ifstream in_;
  mutable std::shared_ptr<const MappedFile> mapping_;
  mutable bool mapped_ = false;
};

// ---- v7.3 through HDF5 ----------------------------------------------------------------------

class H5Id {
 public:
  H5Id() = default;
  H5Id(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~H5Id() { reset(); }
  H5Id(H5Id&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
  H5Id& operator=(H5Id&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      close_ = o.close_;
      o.id_ = -1;
    }
    return *this;
  }
  H5Id(const H5Id&) = delete;
  H5Id& operator=(const H5Id&) = delete;
  [[nodiscard]] hid_t get() const { return id_; }
  [[nodiscard]] bool valid() const { return id_ >= 0; }
  void reset() {
    if (id_ >= 0 && close_ != nullptr) (void)close_(id_);
    id_ = -1;
  }

 private:
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

// An HDF5 file open for reading. Only ever inside an isolated child (io/isolated.hpp): this
// process never calls HDF5, so a fault of the library on a corrupt file stays in the child.
class H5File {
 public:
  explicit H5File(fs::path f) : file_(std::move(f)) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors become InputErrors
    std::error_code ec;
    file_size_ = fs::file_size(file_, ec);
    if (ec) throw InputError(source(), "file", "a readable file", "cannot determine its size");
    h5_ = H5Id(H5Fopen(file_.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
    if (!h5_.valid()) throw InputError(source(), "file", "a MAT v7.3 (HDF5) file HDF5 can open", "HDF5 cannot open it (corrupt?)");
  }
  [[nodiscard]] std::string source() const { return file_.string(); }
  [[nodiscard]] hid_t root() const { return h5_.get(); }
  [[nodiscard]] unsigned long long file_size() const { return file_size_; }

 private:
  fs::path file_;
  H5Id h5_;
  unsigned long long file_size_ = 0;
};

// What a dataset or group holds, from its MATLAB_class attribute (any string padding, fixed or
// variable length) or, without one (plain h5py), from its HDF5 type.
struct H5Var {
  H5Id obj;
  bool group = false;
  matio_classes cls = MAT_C_EMPTY;
  bool complex = false;
  bool logical = false;
  bool empty_flag = false;     // MATLAB_empty: the data are the dimensions
  std::vector<size_t> dims;    // MATLAB order (HDF5's reversed)
  std::string class_name;
};

std::string read_string_attribute(hid_t obj, const char* name, const std::string& source, const std::string& field) {
  if (H5Aexists(obj, name) <= 0) return "";
  const H5Id attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  if (!attr.valid()) throw InputError(source, field, "a readable " + std::string(name) + " attribute", "HDF5 cannot open it");
  // One string: H5Aread writes every element, and the buffers below hold one (an array of 40
  // strings overran the stack pointer or the heap buffer; found by fuzz_mat_timeseries).
  const H5Id space(H5Aget_space(attr.get()), H5Sclose);
  const hssize_t count = space.valid() ? H5Sget_simple_extent_npoints(space.get()) : -1;
  if (count != 1) {
    throw InputError(source, field, std::string(name) + " as one string", count < 0 ? std::string("an unreadable shape") : std::to_string(count) + " elements");
  }
  const H5Id type(H5Aget_type(attr.get()), H5Tclose);
  if (!type.valid() || H5Tget_class(type.get()) != H5T_STRING) {
    throw InputError(source, field, std::string(name) + " as a string attribute", "another type");
  }
  const htri_t variable = H5Tis_variable_str(type.get());
  if (variable < 0) throw InputError(source, field, "a readable " + std::string(name) + " attribute", "an unreadable string type");
  std::string out;
  if (variable > 0) {
    const H5Id mem(H5Tcopy(H5T_C_S1), H5Tclose);
    // Same character set as the file's (h5py writes UTF-8): HDF5 converts no other way.
    if (!mem.valid() || H5Tset_size(mem.get(), H5T_VARIABLE) < 0 || H5Tset_cset(mem.get(), H5Tget_cset(type.get())) < 0) {
      throw InputError(source, field, "a readable " + std::string(name) + " attribute", "an unreadable string type");
    }
    char* value = nullptr;
    if (H5Aread(attr.get(), mem.get(), &value) < 0 || value == nullptr) {
      throw InputError(source, field, "a readable " + std::string(name) + " attribute", "HDF5 read failed");
    }
    out.assign(value, strnlen(value, 256));
    std::free(value);
  } else {
    const size_t size = H5Tget_size(type.get());
    if (size == 0 || size > 256) throw InputError(source, field, std::string(name) + " of 1 to 256 characters", std::to_string(size));
    std::vector<char> buf(size + 1, '\0');
    // Read with the attribute's own type: no conversion between paddings (matio converts a
    // NULLPAD "double" into a NULLTERM one and loses the last letter).
    if (H5Aread(attr.get(), type.get(), buf.data()) < 0) {
      throw InputError(source, field, "a readable " + std::string(name) + " attribute", "HDF5 read failed");
    }
    out.assign(buf.data(), strnlen(buf.data(), size));
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == '\0')) out.pop_back();
  return out;
}

// The `units` attribute of a dataset, spelled units, unit, Units, Unit or UNITS ("" when none).
std::string read_unit_attribute(hid_t obj, const std::string& source, const std::string& field) {
  for (const char* name : {"units", "unit", "Units", "Unit", "UNITS"}) {
    if (H5Aexists(obj, name) > 0) return read_string_attribute(obj, name, source, field + " (attribute " + name + ")");
  }
  return "";
}

// The string attributes of a group other than MATLAB's own (MATLAB_class, ...), at most 4096.
std::vector<std::pair<std::string, std::string>> read_group_attributes(hid_t obj, const std::string& source, const std::string& field) {
  std::vector<std::string> names;
  hsize_t idx = 0;
  const auto collect = [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
    auto* out = static_cast<std::vector<std::string>*>(data);
    if (out->size() > 4096) return 1;
    out->emplace_back(name);
    return 0;
  };
  if (H5Aiterate2(obj, H5_INDEX_NAME, H5_ITER_INC, &idx, collect, &names) < 0) {
    throw InputError(source, field, "readable attributes", "HDF5 cannot list them");
  }
  std::vector<std::pair<std::string, std::string>> out;
  for (const std::string& name : names) {
    if (name.rfind("MATLAB_", 0) == 0) continue;
    const H5Id attr(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose);
    const H5Id type(attr.valid() ? H5Aget_type(attr.get()) : -1, H5Tclose);
    if (!type.valid() || H5Tget_class(type.get()) != H5T_STRING) continue;  // numbers are no units
    out.emplace_back(name, read_string_attribute(obj, name.c_str(), source, field + " (attribute " + name + ")"));
  }
  return out;
}

bool read_flag_attribute(hid_t obj, const char* name, const std::string& source, const std::string& field) {
  if (H5Aexists(obj, name) <= 0) return false;
  const H5Id attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  const H5Id space(attr.valid() ? H5Aget_space(attr.get()) : -1, H5Sclose);
  if (!space.valid() || H5Sget_simple_extent_npoints(space.get()) != 1) {
    throw InputError(source, field, std::string(name) + " as one integer", "another shape");
  }
  long long v = 0;
  if (H5Aread(attr.get(), H5T_NATIVE_LLONG, &v) < 0) throw InputError(source, field, std::string(name) + " as an integer", "HDF5 read failed");
  return v != 0;
}

matio_classes class_from_name(const std::string& c) {
  static const std::pair<const char*, matio_classes> kClasses[] = {
      {"double", MAT_C_DOUBLE}, {"single", MAT_C_SINGLE}, {"int8", MAT_C_INT8},     {"uint8", MAT_C_UINT8},
      {"int16", MAT_C_INT16},   {"uint16", MAT_C_UINT16}, {"int32", MAT_C_INT32},   {"uint32", MAT_C_UINT32},
      {"int64", MAT_C_INT64},   {"uint64", MAT_C_UINT64}, {"char", MAT_C_CHAR},     {"logical", MAT_C_UINT8},
      {"struct", MAT_C_STRUCT}, {"cell", MAT_C_CELL},     {"function_handle", MAT_C_FUNCTION}};
  for (const auto& [name, cls] : kClasses) {
    if (c == name) return cls;
  }
  return MAT_C_OBJECT;  // a class name of its own: a MATLAB object
}

bool is_complex_type(hid_t type) {
  if (H5Tget_class(type) != H5T_COMPOUND || H5Tget_nmembers(type) != 2) return false;
  return H5Tget_member_index(type, "real") >= 0 && H5Tget_member_index(type, "imag") >= 0;
}

H5Var describe_h5_object(const H5File& in, H5Id obj, const std::string& field);

H5Var open_h5_var(const H5File& in, hid_t parent, const std::string& name, const std::string& field) {
  if (H5Lexists(parent, name.c_str(), H5P_DEFAULT) <= 0) {
    throw InputError(in.source(), field, "a variable of the file", "none of that name");
  }
  H5Id obj(H5Oopen(parent, name.c_str(), H5P_DEFAULT), H5Oclose);
  if (!obj.valid()) throw InputError(in.source(), field, "a readable variable", "HDF5 cannot open it");
  return describe_h5_object(in, std::move(obj), field);
}

// What an open dataset or group holds (its class, shape, flags).
H5Var describe_h5_object(const H5File& in, H5Id obj, const std::string& field) {
  const std::string source = in.source();
  H5Var v;
  const H5I_type_t kind = H5Iget_type(obj.get());
  v.class_name = read_string_attribute(obj.get(), "MATLAB_class", source, field);
  if (kind == H5I_GROUP) {
    v.group = true;
    v.cls = v.class_name.empty() || v.class_name == "struct" ? MAT_C_STRUCT : class_from_name(v.class_name);
    v.dims = {1, 1};
    v.obj = std::move(obj);
    return v;
  }
  if (kind != H5I_DATASET) throw InputError(source, field, "a dataset or a group", "another HDF5 object");
  const H5Id type(H5Dget_type(obj.get()), H5Tclose);
  const H5Id space(H5Dget_space(obj.get()), H5Sclose);
  if (!type.valid() || !space.valid()) throw InputError(source, field, "a readable dataset", "HDF5 cannot read its type or shape");
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 0 || rank > 32) throw InputError(source, field, "a dataset of 0 to 32 dimensions", "an unreadable shape");
  std::vector<hsize_t> h5dims(static_cast<size_t>(rank));
  if (rank > 0 && H5Sget_simple_extent_dims(space.get(), h5dims.data(), nullptr) < 0) {
    throw InputError(source, field, "a readable dataset", "HDF5 cannot read its dimensions");
  }
  v.empty_flag = read_flag_attribute(obj.get(), "MATLAB_empty", source, field);
  v.complex = is_complex_type(type.get());
  v.logical = v.class_name == "logical";
  if (!v.class_name.empty()) {
    v.cls = class_from_name(v.class_name);
  } else {
    switch (H5Tget_class(type.get())) {
      case H5T_FLOAT: v.cls = H5Tget_size(type.get()) == 4 ? MAT_C_SINGLE : MAT_C_DOUBLE; break;
      case H5T_INTEGER: v.cls = MAT_C_DOUBLE; break;
      case H5T_COMPOUND: v.cls = v.complex ? MAT_C_DOUBLE : MAT_C_OBJECT; break;
      case H5T_STRING: v.cls = MAT_C_CHAR; break;
      default: v.cls = MAT_C_OBJECT; break;
    }
  }
  for (int i = rank - 1; i >= 0; --i) v.dims.push_back(static_cast<size_t>(h5dims[static_cast<size_t>(i)]));
  if (rank == 0) v.dims = {1, 1};
  if (rank == 1) v.dims.push_back(1);
  if (v.empty_flag) {
    // MATLAB writes an empty array as its dimensions (with a zero among them).
    const hssize_t n = H5Sget_simple_extent_npoints(space.get());
    if (n < 1 || n > 32) throw InputError(source, field, "the dimensions of an empty array (MATLAB_empty)", std::to_string(n) + " values");
    std::vector<unsigned long long> d(static_cast<size_t>(n));
    if (H5Dread(obj.get(), H5T_NATIVE_ULLONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, d.data()) < 0) {
      throw InputError(source, field, "the dimensions of an empty array (MATLAB_empty)", "HDF5 read failed");
    }
    if (std::none_of(d.begin(), d.end(), [](unsigned long long x) { return x == 0; })) {
      throw InputError(source, field, "an empty array (MATLAB_empty = 1: dimensions with a zero)",
                       "dimensions " + shape_text(d) + " holding no zero");
    }
    v.dims.assign(d.begin(), d.end());
    if (v.dims.size() == 1) v.dims.push_back(0);
  }
  v.obj = std::move(obj);
  return v;
}

size_t product(const std::vector<size_t>& dims) {
  size_t n = 1;
  for (size_t d : dims) n = d == 0 || n == 0 ? 0 : (n > (size_t{1} << 50) / d ? (size_t{1} << 50) : n * d);
  return n;
}

// The data of a dataset must be in the file: uncompressed, the bytes the dimensions need;
// filtered (deflate), at most kMaxInflation times the stored bytes once inflated.
void check_h5_storage(const H5File& in, const H5Var& v, const std::string& field) {
  const std::string source = in.source();
  const size_t n = product(v.dims);
  if (n == 0 || v.empty_flag) return;
  const H5Id type(H5Dget_type(v.obj.get()), H5Tclose);
  const H5Id dcpl(H5Dget_create_plist(v.obj.get()), H5Pclose);
  if (!type.valid() || !dcpl.valid()) throw InputError(source, field, "a readable dataset", "HDF5 cannot read its layout");
  const size_t element = H5Tget_size(type.get());
  if (element == 0) throw InputError(source, field, "a readable dataset", "an element size of 0");
  const double declared = static_cast<double>(n) * static_cast<double>(element);
  const double stored = static_cast<double>(std::min<unsigned long long>(H5Dget_storage_size(v.obj.get()), in.file_size()));
  const int filters = H5Pget_nfilters(dcpl.get());
  if (filters < 0) throw InputError(source, field, "a readable dataset", "HDF5 cannot read its filters");
  const std::string shape = shape_text(v.dims);
  if (filters == 0 && stored < declared) {
    throw InputError(source, field + " (declared " + shape + ")",
                     bytes_text(static_cast<unsigned long long>(declared)) + " of data in the file",
                     bytes_text(static_cast<unsigned long long>(stored)));
  }
  if (filters > 0 && declared > kMaxInflation * stored) {
    throw InputError(source, field + " (declared " + shape + ")",
                     "at most " + std::to_string(static_cast<long long>(kMaxInflation)) + " times its " +
                         bytes_text(static_cast<unsigned long long>(stored)) + " of compressed data",
                     bytes_text(static_cast<unsigned long long>(declared)) + " once inflated");
  }
}

MatValue read_h5_var(const H5File& in, hid_t parent, const std::string& name, const std::string& field, int depth);
MatValue read_h5_data(const H5File& in, const H5Var& v, const std::string& name, const std::string& field, size_t n);

MatValue read_h5_struct(const H5File& in, const H5Var& v, const std::string& name, const std::string& field, int depth) {
  const std::string source = in.source();
  if (depth > 16) throw InputError(source, field, "structs nested at most 16 deep", "deeper nesting");
  std::vector<std::string> names;
  hsize_t idx = 0;
  const auto collect = [](hid_t, const char* link, const H5L_info_t*, void* data) -> herr_t {
    auto* out = static_cast<std::vector<std::string>*>(data);
    if (out->size() > 4096) return 1;
    out->emplace_back(link);
    return 0;
  };
  if (H5Literate(v.obj.get(), H5_INDEX_NAME, H5_ITER_INC, &idx, collect, &names) < 0) {
    throw InputError(source, field, "a readable struct", "HDF5 cannot list its fields");
  }
  if (names.size() > 4096) throw InputError(source, field, "a struct of at most 4096 fields", "more");
  MatValue out(name, MAT_C_STRUCT, {1, 1});
  out.field_names = names;
  out.attributes = read_group_attributes(v.obj.get(), source, field);
  for (const auto& n : names) {
    out.items.push_back(read_h5_var(in, v.obj.get(), n, field + "." + n, depth + 1));
    out.items.back().name = n;
  }
  return out;
}

// A variable of the file as the reader returns it (numeric classes as doubles), straight from
// HDF5 (no matio).
MatValue read_h5_array(const H5File& in, const H5Var& v, const std::string& name, const std::string& field);

// A cell's elements of at most this many values in all are read (units and channel-name cells);
// a larger cell comes back as its header only.
constexpr size_t kMaxCellValues = size_t{1} << 20;

// A v7.3 cell: a dataset of object references (class cell) to the elements' datasets in #refs#
// (MATLAB, hdf5storage). Read when every element is a numeric or char array and all hold at most
// kMaxCellValues values; a cell of structs or cells, or a larger one, comes back as its header
// only (has_data false), as before cells were read. A reference that leads nowhere is an InputError.
MatValue read_h5_cell(const H5File& in, const H5Var& v, const std::string& name, const std::string& field) {
  MatValue out(name, MAT_C_CELL, v.dims);
  const size_t n = product(v.dims);
  out.has_data = n == 0;  // an empty cell is complete
  const H5Id type(H5Dget_type(v.obj.get()), H5Tclose);
  if (n == 0 || n > kMaxCellValues || v.empty_flag || !type.valid() || H5Tget_class(type.get()) != H5T_REFERENCE) return out;
  check_h5_storage(in, v, field);
  std::vector<hobj_ref_t> refs(n);
  if (H5Dread(v.obj.get(), H5T_STD_REF_OBJ, H5S_ALL, H5S_ALL, H5P_DEFAULT, refs.data()) < 0) {
    throw InputError(in.source(), field, "a cell's references HDF5 can read", "the read failed (corrupt or truncated file)");
  }
  std::vector<H5Var> elements;
  size_t values = 0;
  for (size_t i = 0; i < n; ++i) {
    const std::string element_field = field + "{" + std::to_string(i + 1) + "}";
    H5Id obj(H5Rdereference2(v.obj.get(), H5P_DEFAULT, H5R_OBJECT, &refs[i]), H5Oclose);
    if (!obj.valid()) throw InputError(in.source(), element_field, "a reference to an object of the file", "a reference HDF5 cannot follow");
    H5Var e = describe_h5_object(in, std::move(obj), element_field);
    if (e.group || (!is_numeric_class(e.cls) && e.cls != MAT_C_CHAR)) return out;  // nested: not read
    values += product(e.dims);
    if (values > kMaxCellValues) return out;
    elements.push_back(std::move(e));
  }
  for (size_t i = 0; i < n; ++i) out.items.push_back(read_h5_array(in, elements[i], "", field + "{" + std::to_string(i + 1) + "}"));
  out.has_data = true;
  return out;
}

MatValue read_h5_var(const H5File& in, hid_t parent, const std::string& name, const std::string& field, int depth) {
  const std::string source = in.source();
  const H5Var v = open_h5_var(in, parent, name, field);
  if (v.group) {
    if (v.cls != MAT_C_STRUCT) throw InputError(source, field, "a struct group", "MATLAB class " + text::quote(v.class_name));
    return read_h5_struct(in, v, name, field, depth);
  }
  if (v.cls == MAT_C_CELL) return read_h5_cell(in, v, name, field);
  if (!is_numeric_class(v.cls) && v.cls != MAT_C_CHAR) {
    // Classes piezobench never reads (object, function handle): the header only.
    MatValue out(name, v.cls, v.dims);
    out.has_data = false;
    return out;
  }
  return read_h5_array(in, v, name, field);
}

// A numeric or char dataset, with its unit attribute.
MatValue read_h5_array(const H5File& in, const H5Var& v, const std::string& name, const std::string& field) {
  const std::string source = in.source();
  const size_t n = product(v.dims);
  check_h5_storage(in, v, field);
  if (n == 0 || v.empty_flag) return MatValue(name, v.cls == MAT_C_CHAR ? MAT_C_CHAR : MAT_C_DOUBLE, v.dims);
  if (v.cls != MAT_C_CHAR) {
    MatValue out = read_h5_data(in, v, name, field, n);
    out.unit = read_unit_attribute(v.obj.get(), source, field);
    return out;
  }
  return read_h5_data(in, v, name, field, n);
}

// The data of a numeric or char dataset of n > 0 elements.
MatValue read_h5_data(const H5File& in, const H5Var& v, const std::string& name, const std::string& field, size_t n) {
  const std::string source = in.source();
  const auto fail_read = [&] { throw InputError(source, field, "data HDF5 can read", "the read failed (corrupt or truncated file)"); };
  if (v.cls == MAT_C_CHAR) {
    std::vector<std::uint16_t> units(n);
    const H5Id ftype(H5Dget_type(v.obj.get()), H5Tclose);
    if (!ftype.valid() || H5Tget_class(ftype.get()) != H5T_INTEGER) {
      throw InputError(source, field, "char data as 16-bit code units", "another HDF5 type");
    }
    if (H5Dread(v.obj.get(), H5T_NATIVE_UINT16, H5S_ALL, H5S_ALL, H5P_DEFAULT, units.data()) < 0) fail_read();
    MatValue out(name, MAT_C_CHAR, v.dims);
    // MATLAB stores char as UTF-16 code units; the text is UTF-8 (as from_matvar makes it).
    const std::vector<double> codes(units.begin(), units.end());
    out.text = utf8_from_units(codes.data(), n);
    return out;
  }
  if (v.complex) {
    const H5Id mem(H5Tcreate(H5T_COMPOUND, 2 * sizeof(double)), H5Tclose);
    if (!mem.valid() || H5Tinsert(mem.get(), "real", 0, H5T_NATIVE_DOUBLE) < 0 ||
        H5Tinsert(mem.get(), "imag", sizeof(double), H5T_NATIVE_DOUBLE) < 0) {
      fail_read();
    }
    std::vector<double> both(2 * n);
    if (H5Dread(v.obj.get(), mem.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, both.data()) < 0) fail_read();
    MatValue out(name, MAT_C_DOUBLE, v.dims, /*complex=*/true);
    out.re.resize(n);
    out.im.resize(n);
    for (size_t i = 0; i < n; ++i) {
      out.re[i] = both[2 * i];
      out.im[i] = both[2 * i + 1];
    }
    return out;
  }
  const H5Id ftype(H5Dget_type(v.obj.get()), H5Tclose);
  if (!ftype.valid() || (H5Tget_class(ftype.get()) != H5T_FLOAT && H5Tget_class(ftype.get()) != H5T_INTEGER)) {
    throw InputError(source, field, "numeric data (integer or floating point)", "another HDF5 type");
  }
  MatValue out(name, MAT_C_DOUBLE, v.dims, /*complex=*/false, v.logical);
  out.re.resize(n);  // read as double straight into place
  if (H5Dread(v.obj.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.re.data()) < 0) fail_read();
  return out;
}

std::vector<std::string> h5_top_level_names(const H5File& in) {
  std::vector<std::string> names;
  hsize_t idx = 0;
  const auto collect = [](hid_t, const char* link, const H5L_info_t*, void* data) -> herr_t {
    auto* out = static_cast<std::vector<std::string>*>(data);
    if (out->size() > (1u << 20)) return 1;
    // MATLAB's own bookkeeping groups (#refs#, #subsystem#) are not variables.
    if (link[0] != '#') out->emplace_back(link);
    return 0;
  };
  if (H5Literate(in.root(), H5_INDEX_NAME, H5_ITER_INC, &idx, collect, &names) < 0) {
    throw InputError(in.source(), "file", "a readable MAT v7.3 file", "HDF5 cannot list its variables");
  }
  if (names.size() > (1u << 20)) throw InputError(in.source(), "file", "a well-formed MAT file", "more than 2^20 variables (corrupt?)");
  return names;
}

// The dataset of a real double vector of exactly `count` elements (class double or none), or an
// invalid H5Var.
std::optional<H5Var> plain_h5_vector(const H5File& in, const std::string& name, Eigen::Index count) {
  if (count <= 0 || H5Lexists(in.root(), name.c_str(), H5P_DEFAULT) <= 0) return std::nullopt;
  H5Var v = open_h5_var(in, in.root(), name, name);
  if (v.group || v.empty_flag || v.complex || v.cls != MAT_C_DOUBLE || static_cast<Eigen::Index>(product(v.dims)) != count ||
      std::count_if(v.dims.begin(), v.dims.end(), [](size_t d) { return d != 1; }) > 1) {
    return std::nullopt;
  }
  const H5Id ftype(H5Dget_type(v.obj.get()), H5Tclose);
  if (!ftype.valid() || (H5Tget_class(ftype.get()) != H5T_FLOAT && H5Tget_class(ftype.get()) != H5T_INTEGER)) return std::nullopt;
  check_h5_storage(in, v, name);
  return v;
}

// Elements [first, first + count) of a vector dataset into out (a hyperslab along its one
// non-singleton dimension).
void read_h5_part(const H5File& in, const H5Var& v, const std::string& name, Eigen::Index first, Eigen::Index count, double* out) {
  const H5Id space(H5Dget_space(v.obj.get()), H5Sclose);
  const int rank = space.valid() ? H5Sget_simple_extent_ndims(space.get()) : -1;
  if (rank < 0 || rank > 32) throw InputError(in.source(), name, "a readable dataset", "HDF5 cannot read its shape");
  std::vector<hsize_t> dims(static_cast<size_t>(rank)), start(static_cast<size_t>(rank), 0), edge(static_cast<size_t>(rank), 1);
  if (rank > 0 && H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) < 0) {
    throw InputError(in.source(), name, "a readable dataset", "HDF5 cannot read its dimensions");
  }
  int along = 0;
  for (int d = 0; d < rank; ++d) {
    if (dims[static_cast<size_t>(d)] != 1) along = d;
  }
  if (rank > 0) {
    start[static_cast<size_t>(along)] = static_cast<hsize_t>(first);
    edge[static_cast<size_t>(along)] = static_cast<hsize_t>(count);
    if (H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start.data(), nullptr, edge.data(), nullptr) < 0) {
      throw InputError(in.source(), name, "a readable dataset", "HDF5 cannot select a part of it");
    }
  }
  const hsize_t mem_dims[1] = {static_cast<hsize_t>(count)};
  const H5Id mem(H5Screate_simple(1, mem_dims, nullptr), H5Sclose);
  if (!mem.valid() || H5Dread(v.obj.get(), H5T_NATIVE_DOUBLE, mem.get(), space.get(), H5P_DEFAULT, out) < 0) {
    throw InputError(in.source(), name, "data HDF5 can read", "the read failed (corrupt or truncated file)");
  }
}

// ---- v7.3: the parent's side ----------------------------------------------------------------
//
// Every operation on a v7.3 file forks a child that opens the file with HDF5, does the one
// operation and sends its result back (io/isolated.hpp); the parent keeps only the file's name
// and its list of variables. The parent checks what it receives as it would a file: bounded
// names, ranks, nesting and sizes (a child whose memory HDF5 corrupted may send anything).

IsolatedOptions isolated_options(const std::string& source) {
  IsolatedOptions o;
  o.source = source;
  o.expected = "a MAT v7.3 (HDF5) file the HDF5 library can read";
  o.failure = "the HDF5 library failed on it";
  return o;
}

// A variable as the reader returns it (MatValue: numeric and char data, struct fields and cells
// recursively), sent by the child.
void put_value(IsolatedOut& out, const MatValue& v) {
  out.put_string(v.name);
  for (std::uint64_t x : {static_cast<std::uint64_t>(v.class_type), static_cast<std::uint64_t>(v.is_complex),
                          static_cast<std::uint64_t>(v.is_logical), static_cast<std::uint64_t>(v.has_data),
                          static_cast<std::uint64_t>(v.dims.size())}) {
    out.put_u64(x);
  }
  for (size_t d : v.dims) out.put_u64(d);
  for (const std::vector<double>* part : {&v.re, &v.im}) {
    out.put_u64(part->size());
    out.put(part->data(), part->size() * sizeof(double));
  }
  out.put_string(v.text);
  out.put_u64(v.field_names.size());
  for (const std::string& f : v.field_names) out.put_string(f);
  out.put_u64(v.items.size());
  for (const MatValue& item : v.items) put_value(out, item);
  out.put_string(v.unit);
  out.put_u64(v.attributes.size());
  for (const auto& [key, text] : v.attributes) {
    out.put_string(key);
    out.put_string(text);
  }
}

// The MatValue put_value sent. `budget`: the bytes of data and the items the answer may still
// hold (a variable of the file cannot hold more: 8 x kMaxInflation x its size), spent as they come.
MatValue get_value(IsolatedIn& in, double& budget, int depth) {
  if (depth > 17) in.malformed("values nested deeper than the reader reads");
  MatValue v;
  v.name = in.get_string(4096);
  const std::uint64_t cls = in.get_u64(), complex = in.get_u64(), logical = in.get_u64(), has_data = in.get_u64(),
                      rank = in.get_u64();
  if (cls > MAT_C_OPAQUE || complex > 1 || logical > 1 || has_data > 1 || rank > 32) in.malformed("a variable header out of range");
  v.class_type = static_cast<matio_classes>(cls);
  v.is_complex = complex != 0;
  v.is_logical = logical != 0;
  v.has_data = has_data != 0;
  for (std::uint64_t d = 0; d < rank; ++d) v.dims.push_back(in.get_u64());
  const auto spend = [&](double bytes) {
    if (bytes > budget) in.malformed("more data than the file can hold");
    budget -= bytes;
  };
  for (std::vector<double>* part : {&v.re, &v.im}) {
    const std::uint64_t n = in.get_u64();
    spend(8.0 * static_cast<double>(n));
    part->resize(n);
    in.get(part->data(), n * sizeof(double));
  }
  v.text = in.get_string(static_cast<std::size_t>(std::min(budget, 1e15)));
  spend(static_cast<double>(v.text.size()));
  const std::uint64_t fields = in.get_u64();
  if (fields > 4096) in.malformed(std::to_string(fields) + " struct fields");
  for (std::uint64_t f = 0; f < fields; ++f) v.field_names.push_back(in.get_string(4096));
  const std::uint64_t items = in.get_u64();
  spend(64.0 * static_cast<double>(items));
  for (std::uint64_t i = 0; i < items; ++i) v.items.push_back(get_value(in, budget, depth + 1));
  v.unit = in.get_string(4096);
  const std::uint64_t attributes = in.get_u64();
  if (attributes > 4096) in.malformed(std::to_string(attributes) + " attributes");
  for (std::uint64_t a = 0; a < attributes; ++a) {
    std::string key = in.get_string(4096);
    v.attributes.emplace_back(std::move(key), in.get_string(4096));
  }
  return v;
}

// A v7.3 file in this process: its name and what the child that opened it listed.
class Mat73Input final : public MatInput {
 public:
  explicit Mat73Input(fs::path f) : MatInput(std::move(f)) {
    std::error_code ec;
    const auto size = fs::file_size(file(), ec);
    if (ec) throw InputError(source(), "file", "a readable file", "cannot determine its size");
    // Doubles from 1-byte integers (8x) of a deflated dataset (kMaxInflation x), see check_h5_storage.
    limit_ = 8.0 * kMaxInflation * static_cast<double>(size) + 4096.0;
    run(
        [&](IsolatedOut& out) {
          H5File h5(file());
          std::vector<MatVarInfo> list;
          std::vector<std::pair<std::string, std::string>> attributes;
          try {
            // h5py users put units on the file itself: f.attrs["units"] = "u=V, de=um".
            attributes = read_group_attributes(h5.root(), h5.source(), "/");
            for (const std::string& name : h5_top_level_names(h5)) {
              const H5Var v = open_h5_var(h5, h5.root(), name, name);
              // Readers size their buffers from this list: the declared size is checked here, first.
              if (!v.group && (is_numeric_class(v.cls) || v.cls == MAT_C_CHAR)) check_h5_storage(h5, v, name);
              list.push_back({name, v.cls, v.complex, v.dims, v.group ? std::string() : read_unit_attribute(v.obj.get(), h5.source(), name)});
            }
          } catch (const InputError& e) {
            // Reported by list_mat_variables, as when the file was read in this process.
            out.put_u64(1);
            out.put_string(e.what());
            return;
          }
          out.put_u64(0);
          out.put_u64(list.size());
          for (const MatVarInfo& v : list) {
            out.put_string(v.name);
            out.put_u64(static_cast<std::uint64_t>(v.class_type));
            out.put_u64(v.is_complex ? 1 : 0);
            out.put_u64(v.dims.size());
            for (size_t d : v.dims) out.put_u64(d);
            out.put_string(v.unit);
          }
          out.put_u64(attributes.size());
          for (const auto& [key, text] : attributes) {
            out.put_string(key);
            out.put_string(text);
          }
        },
        [&](IsolatedIn& in) {
          if (in.get_u64() != 0) {
            list_error_ = in.get_string();
            return;
          }
          const std::uint64_t n = in.get_u64();
          if (n > (1u << 20)) in.malformed(std::to_string(n) + " variables");
          for (std::uint64_t i = 0; i < n; ++i) {
            MatVarInfo v;
            v.name = in.get_string(4096);
            const std::uint64_t cls = in.get_u64(), complex = in.get_u64(), rank = in.get_u64();
            if (cls > MAT_C_OPAQUE || complex > 1 || rank > 32) in.malformed("a variable header out of range");
            v.class_type = static_cast<matio_classes>(cls);
            v.is_complex = complex != 0;
            for (std::uint64_t d = 0; d < rank; ++d) v.dims.push_back(in.get_u64());
            v.unit = in.get_string(4096);
            list_.push_back(std::move(v));
          }
          const std::uint64_t attributes = in.get_u64();
          if (attributes > 4097) in.malformed(std::to_string(attributes) + " attributes");
          for (std::uint64_t a = 0; a < attributes; ++a) {
            std::string key = in.get_string(4096);
            attributes_.emplace_back(std::move(key), in.get_string(4096));
          }
        });
  }
  [[nodiscard]] bool v73() const override { return true; }
  [[nodiscard]] std::string source() const { return file().string(); }
  [[nodiscard]] double limit() const { return limit_; }
  [[nodiscard]] const std::vector<MatVarInfo>& list() const {
    if (!list_error_.empty()) throw InputError(list_error_);
    return list_;
  }
  // The root group's string attributes (read_group_attributes).
  [[nodiscard]] const std::vector<std::pair<std::string, std::string>>& attributes() const {
    if (!list_error_.empty()) throw InputError(list_error_);
    return attributes_;
  }
  // Runs `child` (given the file open in HDF5) isolated, `parent` on its answer.
  void run(const std::function<void(IsolatedOut&)>& child, const std::function<void(IsolatedIn&)>& parent) const {
    run_isolated(isolated_options(source()), child, parent);
  }

 private:
  std::vector<MatVarInfo> list_;
  std::vector<std::pair<std::string, std::string>> attributes_;
  std::string list_error_;
  double limit_ = 0.0;
};

// ---- matio fast path (v5) -------------------------------------------------------------------

// The header of a real, uncompressed double vector of exactly `count` elements, or null.
MatVarPtr plain_double_vector_info(mat_t* mat, const std::string& name, Eigen::Index count) {
  if (count == 0 || count > std::numeric_limits<int>::max()) return nullptr;
  MatVarPtr info(Mat_VarReadInfo(mat, name.c_str()));
  if (!info || info->class_type != MAT_C_DOUBLE || info->isComplex != 0 || info->isLogical != 0 ||
      info->compression != MAT_COMPRESSION_NONE || static_cast<Eigen::Index>(element_count(*info)) != count ||
      std::count_if(info->dims, info->dims + info->rank, [](size_t d) { return d != 1; }) > 1) {
    (void)take_matio_message();
    return nullptr;
  }
  return info;
}

// Elements [first, first + count) of a v5 vector variable (header `info`): Mat_VarReadDataLinear,
// an fread into `out`. (matio 1.5.23 reads zeros for a v5 row vector through Mat_VarReadData at a
// nonzero start.)
bool read_v5_part(mat_t* mat, matvar_t* info, Eigen::Index first, Eigen::Index count, double* out) {
  return Mat_VarReadDataLinear(mat, info, out, static_cast<int>(first), 1, static_cast<int>(count)) == 0;
}

const Mat5Input* as_v5(const MatInput* in) { return in->v73() ? nullptr : static_cast<const Mat5Input*>(in); }
const Mat73Input* as_v73(const MatInput* in) { return in->v73() ? static_cast<const Mat73Input*>(in) : nullptr; }

// A plain double vector of exactly `count` elements, its elements [first, first + count) sent by
// the child in pieces of `chunk`, each handed to `take` (false: the variable is something else).
bool read_h5_vector(const Mat73Input& in, const std::string& name, Eigen::Index count, Eigen::Index first, Eigen::Index length,
                    Eigen::Index chunk, const std::function<void(Eigen::Index first, Eigen::Index count, IsolatedIn&)>& take) {
  bool plain = false;
  const fs::path file = in.file();
  in.run(
      [&](IsolatedOut& out) {
        H5File h5(file);
        const std::optional<H5Var> v = plain_h5_vector(h5, name, count);
        out.put_u64(v ? 1 : 0);
        if (!v) return;
        std::vector<double> piece(static_cast<size_t>(std::min(chunk, length)));
        for (Eigen::Index at = first; at < first + length; at += chunk) {
          const Eigen::Index n = std::min(chunk, first + length - at);
          read_h5_part(h5, *v, name, at, n, piece.data());
          out.put(piece.data(), static_cast<size_t>(n) * sizeof(double));
        }
      },
      [&](IsolatedIn& answer) {
        plain = answer.get_u64() != 0;
        if (!plain) return;
        for (Eigen::Index at = first; at < first + length; at += chunk) take(at, std::min(chunk, first + length - at), answer);
      });
  return plain;
}

// The own reader's plain double vector of exactly `count` elements, or null.
const V5Variable* own_plain_vector(const Mat5Input& in, const std::string& name, Eigen::Index count) {
  const V5Variable* v = in.find(name);
  return v != nullptr && count > 0 && v->count == static_cast<unsigned long long>(count) &&
                 std::count_if(v->dims.begin(), v->dims.end(), [](size_t d) { return d != 1; }) <= 1
             ? v
             : nullptr;
}

}  // namespace

bool numbers_to_doubles(std::uint32_t type, const void* data, size_t n, double* out) {
  const auto* raw = static_cast<const unsigned char*>(data);
  const auto convert = [&](auto zero) {
    using T = decltype(zero);
    for (size_t i = 0; i < n; ++i) {
      T v;
      std::memcpy(&v, raw + i * sizeof(T), sizeof(T));
      out[i] = static_cast<double>(v);
    }
    return true;
  };
  switch (type) {
    case 1: return convert(std::int8_t{});
    case 2: case 16: return convert(std::uint8_t{});   // uint8, utf8
    case 3: return convert(std::int16_t{});
    case 4: case 17: return convert(std::uint16_t{});  // uint16, utf16
    case 5: return convert(std::int32_t{});
    case 6: case 18: return convert(std::uint32_t{});  // uint32, utf32
    case 7: return convert(float{});
    case 9: std::memcpy(out, data, n * sizeof(double)); return true;
    case 12: return convert(std::int64_t{});
    case 13: return convert(std::uint64_t{});
    default: return false;
  }
}

MatFilePtr open_mat_for_reading(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw InputError(file.string(), "file", "an existing file", "no such file");
  if (fs::is_directory(file, ec)) throw InputError(file.string(), "file", "a regular file", "a directory");
  std::vector<V5Variable> vars;
  bool own = false;
  if (check_mat_file(file, vars, own)) return std::make_unique<Mat73Input>(file);
  if (own) return std::make_unique<Mat5Input>(file, nullptr, std::move(vars));
  install_matio_logger();
  (void)take_matio_message();
  MatioPtr mat(Mat_Open(file.c_str(), MAT_ACC_RDONLY));
  if (!mat) {
    throw InputError(file.string(), "file", "a MAT file (v5, v7 or v7.3)", with_matio_reason("matio cannot open it"));
  }
  return std::make_unique<Mat5Input>(file, std::move(mat), std::move(vars));
}

bool read_without_matio(const MatInput* in) {
  const Mat5Input* v5 = as_v5(in);
  return v5 != nullptr && v5->mat() == nullptr;
}

std::vector<MatVarInfo> list_mat_variables(MatInput* in, const fs::path& file) {
  std::vector<MatVarInfo> out;
  if (const Mat73Input* h5 = as_v73(in)) return h5->list();
  if (read_without_matio(in)) {
    for (const V5Variable& v : as_v5(in)->vars()) out.push_back({v.name, v.class_type, v.is_complex, v.dims, ""});
    return out;
  }
  mat_t* mat = as_v5(in)->mat();
  if (Mat_Rewind(mat) != 0) throw InputError(file.string(), "file", "a readable MAT file", with_matio_reason("cannot rewind"));
  // A corrupt file can make matio loop on garbage; a real file never holds this many variables.
  constexpr size_t kMaxVariables = 1u << 20;
  for (;;) {
    MatVarPtr var(Mat_VarReadNextInfo(mat));
    if (!var) break;
    MatVarInfo info;
    info.name = var->name != nullptr ? var->name : "";
    info.class_type = var->class_type;
    info.is_complex = var->isComplex != 0;
    if (var->dims != nullptr) info.dims.assign(var->dims, var->dims + std::max(var->rank, 0));
    out.push_back(std::move(info));
    if (out.size() > kMaxVariables) {
      throw InputError(file.string(), "file", "a well-formed MAT file", "more than 2^20 variables (corrupt?)");
    }
  }
  const std::string reason = take_matio_message();
  if (out.empty() && !reason.empty()) {
    throw InputError(file.string(), "file", "a well-formed MAT file", "matio: " + reason);
  }
  return out;
}

std::vector<std::pair<std::string, std::string>> mat_file_attributes(MatInput* in) {
  if (const Mat73Input* h5 = as_v73(in)) return h5->attributes();
  return {};
}

MatValue read_mat_variable(MatInput* in, const fs::path& file, const std::string& name) {
  if (const Mat73Input* h5 = as_v73(in)) {
    MatValue value;
    h5->run(
        [&](IsolatedOut& out) {
          H5File f(file);
          put_value(out, read_h5_var(f, f.root(), name, name, 0));
        },
        [&](IsolatedIn& answer) {
          double budget = h5->limit();
          value = get_value(answer, budget, 0);
        });
    return value;
  }
  if (read_without_matio(in)) {
    const V5Variable* v = as_v5(in)->find(name);
    if (v == nullptr) throw InputError(file.string(), name, "a variable of the file", "none of that name");
    return as_v5(in)->decode(*v);
  }
  mat_t* mat = as_v5(in)->mat();
  (void)take_matio_message();
  MatVarPtr info(Mat_VarReadInfo(mat, name.c_str()));
  if (!info) {
    throw InputError(file.string(), name, "a readable variable", with_matio_reason("matio cannot read it (missing or corrupt)"));
  }
  const matio_classes c = info->class_type;
  if (!is_numeric_class(c) && c != MAT_C_CHAR && c != MAT_C_STRUCT && c != MAT_C_CELL && c != MAT_C_EMPTY) {
    return from_matvar(*info, file.string());
  }
  MatVarPtr var(Mat_VarRead(mat, name.c_str()));
  if (!var) {
    throw InputError(file.string(), name, "a readable variable", with_matio_reason("matio cannot read it (missing or corrupt)"));
  }
  // matio may return the header of a variable whose data it could not read (truncated file).
  if (var->class_type != MAT_C_STRUCT && var->class_type != MAT_C_CELL && var->class_type != MAT_C_EMPTY &&
      element_count(*var) > 0 && var->data == nullptr) {
    throw InputError(file.string(), name, "a complete variable", with_matio_reason("its data cannot be read (truncated file?)"));
  }
  return from_matvar(*var, file.string());
}

bool read_double_vector_into(MatInput* in, const std::string& name, Eigen::Ref<Eigen::VectorXd> out, Eigen::Index chunk,
                             const std::function<void(Eigen::Index, Eigen::Index)>& on_chunk) {
  if (out.innerStride() != 1) return false;
  const Eigen::Index n = out.size();
  const Eigen::Index step = chunk > 0 ? chunk : n;
  if (const Mat73Input* h5 = as_v73(in)) {
    // Each piece lands in `out` as it arrives, and is looked at before the next one is read.
    return read_h5_vector(*h5, name, n, 0, n, step, [&](Eigen::Index first, Eigen::Index count, IsolatedIn& answer) {
      answer.get(out.data() + first, static_cast<size_t>(count) * sizeof(double));
      if (on_chunk) on_chunk(first, count);
    });
  }
  if (read_without_matio(in)) {
    const V5Variable* v = own_plain_vector(*as_v5(in), name, n);
    if (v == nullptr) return false;
    for (Eigen::Index first = 0; first < n; first += step) {
      const Eigen::Index count = std::min(step, n - first);
      as_v5(in)->read_at(v->offset + 8 * static_cast<unsigned long long>(first), out.data() + first, 8 * static_cast<unsigned long long>(count));
      if (on_chunk) on_chunk(first, count);
    }
    return true;
  }
  mat_t* mat = as_v5(in)->mat();
  const MatVarPtr info = plain_double_vector_info(mat, name, n);
  if (!info) return false;
  for (Eigen::Index first = 0; first < n; first += step) {
    const Eigen::Index count = std::min(step, n - first);
    if (!read_v5_part(mat, info.get(), first, count, out.data() + first)) {
      (void)take_matio_message();
      return false;
    }
    if (on_chunk) on_chunk(first, count);
  }
  (void)take_matio_message();
  return true;
}

std::optional<double> read_double_element(MatInput* in, const std::string& name, Eigen::Index count, Eigen::Index index) {
  if (index < 0 || index >= count) return std::nullopt;
  double value = 0.0;
  if (const Mat73Input* h5 = as_v73(in)) {
    const bool plain = read_h5_vector(*h5, name, count, index, 1, 1,
                                      [&](Eigen::Index, Eigen::Index, IsolatedIn& answer) { answer.get(&value, sizeof value); });
    if (!plain) return std::nullopt;
    return value;
  }
  if (read_without_matio(in)) {
    const V5Variable* v = own_plain_vector(*as_v5(in), name, count);
    if (v == nullptr) return std::nullopt;
    as_v5(in)->read_at(v->offset + 8 * static_cast<unsigned long long>(index), &value, 8);
    return value;
  }
  mat_t* mat = as_v5(in)->mat();
  const MatVarPtr info = plain_double_vector_info(mat, name, count);
  if (!info) return std::nullopt;
  const bool ok = read_v5_part(mat, info.get(), index, 1, &value);
  (void)take_matio_message();
  if (!ok) return std::nullopt;
  return value;
}

std::optional<MappedDoubles> map_double_vector(MatInput* in, const std::string& name, std::size_t count) {
  const Mat5Input* v5 = as_v5(in);
  if (v5 == nullptr || count == 0) return std::nullopt;
  const V5Variable* it = v5->find(name);
  if (it == nullptr || it->count != count) return std::nullopt;
  const std::shared_ptr<const MappedFile>& file = v5->mapping();
  if (!file) return std::nullopt;
  // The mapping is of the file as it is now: a file that changed since it was checked is refused.
  const double* data = file->doubles(static_cast<std::size_t>(it->offset), count);
  if (data == nullptr) return std::nullopt;
  return MappedDoubles{data, file};
}

}  // namespace piezobench::io::detail
