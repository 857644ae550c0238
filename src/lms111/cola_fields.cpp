#include "dormant_tree_modeling/lms111/cola_fields.h"

#include <climits>
#include <cstdio>
#include <cstring>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace lms111 {

namespace {

void checkFits(std::uint64_t value, int bits) {
  if (bits < 64 && (value >> bits) != 0) {
    throw Error(
        ErrorCode::INVALID_ARGUMENT,
        "value " + std::to_string(value) + " does not fit in " + std::to_string(bits) + " bits");
  }
}

std::uint32_t floatBits(float f) {
  std::uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return bits;
}

float bitsFloat(std::uint32_t bits) {
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

}  // namespace

void FieldReader::fail(const char* field, std::size_t position, const std::string& what) const {
  throw Error(ErrorCode::PARSE_ERROR, std::string("telegram field '") + field + "' at offset " +
                                          std::to_string(position) + ": " + what);
}

// ---- CoLa-A ---------------------------------------------------------------------------------

std::string ColaAReader::token(const char* field) {
  if (pos_ < text_.size() && pos_ > 0) {
    if (text_[pos_] != ' ')
      fail(field, pos_, "expected a space");
    ++pos_;
  }
  if (pos_ >= text_.size())
    fail(field, pos_, "the telegram ends early");
  const std::size_t end = text_.find(' ', pos_);
  const std::size_t stop = end == std::string::npos ? text_.size() : end;
  if (stop == pos_)
    fail(field, pos_, "empty field (two spaces)");
  std::string t = text_.substr(pos_, stop - pos_);
  pos_ = stop;
  return t;
}

std::uint64_t ColaAReader::unsignedValue(const char* field, int bits) {
  const std::string t = token(field);
  const auto v = parseColaNumber(t);
  if (!v || *v < 0)
    fail(field, pos_, "'" + printableBytes(t, 40) + "' is not an unsigned number");
  if (bits < 64 && static_cast<std::uint64_t>(*v) >> bits)
    fail(field, pos_, "'" + printableBytes(t, 40) + "' exceeds " + std::to_string(bits) + " bits");
  return static_cast<std::uint64_t>(*v);
}

std::int32_t ColaAReader::signedValue(const char* field) {
  const std::string t = token(field);
  const auto v = parseColaNumber(t);
  if (!v)
    fail(field, pos_, "'" + printableBytes(t, 40) + "' is not a number");
  if (t[0] == '+' || t[0] == '-') {
    if (*v < INT32_MIN || *v > INT32_MAX)
      fail(field, pos_, "'" + printableBytes(t, 40) + "' exceeds 32 bits");
    return static_cast<std::int32_t>(*v);
  }
  if (static_cast<std::uint64_t>(*v) >> 32)
    fail(field, pos_, "'" + printableBytes(t, 40) + "' exceeds 32 bits");
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(*v));
}

float ColaAReader::floatValue(const char* field) {
  const std::string t = token(field);
  const auto v = parseColaNumber(t);
  if (!v || t[0] == '+' || t[0] == '-' || static_cast<std::uint64_t>(*v) >> 32)
    fail(field, pos_, "'" + printableBytes(t, 40) + "' is not a hex IEEE-754 float");
  return bitsFloat(static_cast<std::uint32_t>(*v));
}

std::string ColaAReader::characters(const char* field, std::size_t length) {
  if (pos_ >= text_.size() || text_[pos_] != ' ')
    fail(field, pos_, "expected a space before the string");
  ++pos_;
  if (length > text_.size() - pos_)
    fail(field, pos_, "string of " + std::to_string(length) + " characters runs past the end");
  std::string s = text_.substr(pos_, length);
  pos_ += length;
  return s;
}

bool ColaAReader::atEnd() const {
  return pos_ >= text_.size() || text_.find_first_not_of(' ', pos_) == std::string::npos;
}

void ColaAWriter::word(const std::string& text) {
  if (!out_.empty())
    out_ += ' ';
  out_ += text;
}

void ColaAWriter::unsignedValue(std::uint64_t value, int bits) {
  checkFits(value, bits);
  char buf[24];
  std::snprintf(buf, sizeof buf, "%llX", static_cast<unsigned long long>(value));
  word(buf);
}

void ColaAWriter::signedValue(std::int32_t value) {
  unsignedValue(static_cast<std::uint32_t>(value), 32);
}

void ColaAWriter::floatValue(float value) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%08X", floatBits(value));
  word(buf);
}

void ColaAWriter::characters(const std::string& text) {
  out_ += ' ';
  out_ += text;
}

// ---- CoLa-B ---------------------------------------------------------------------------------

std::string ColaBReader::word(const char* field) {
  if (pos_ >= data_.size())
    fail(field, pos_, "the telegram ends early");
  const std::size_t end = data_.find(' ', pos_);
  const std::size_t stop = end == std::string::npos ? data_.size() : end;
  if (stop == pos_)
    fail(field, pos_, "empty word");
  std::string w = data_.substr(pos_, stop - pos_);
  pos_ = stop == data_.size() ? stop : stop + 1;
  return w;
}

std::uint64_t ColaBReader::bigEndian(const char* field, int bytes) {
  if (static_cast<std::size_t>(bytes) > data_.size() - std::min(pos_, data_.size()))
    fail(field, pos_, "the telegram ends early (" + std::to_string(bytes) + " bytes needed)");
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i)
    v = (v << 8) | static_cast<unsigned char>(data_[pos_++]);
  return v;
}

std::uint64_t ColaBReader::unsignedValue(const char* field, int bits) {
  if (bits != 8 && bits != 16 && bits != 32 && bits != 64)
    fail(field, pos_, "no CoLa-B field is " + std::to_string(bits) + " bits wide");
  return bigEndian(field, bits / 8);
}

std::int32_t ColaBReader::signedValue(const char* field) {
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(bigEndian(field, 4)));
}

float ColaBReader::floatValue(const char* field) {
  return bitsFloat(static_cast<std::uint32_t>(bigEndian(field, 4)));
}

std::string ColaBReader::label(const char* field, std::size_t width) {
  return characters(field, width);
}

std::string ColaBReader::characters(const char* field, std::size_t length) {
  if (length > data_.size() - std::min(pos_, data_.size()))
    fail(field, pos_, "string of " + std::to_string(length) + " bytes runs past the end");
  std::string s = data_.substr(pos_, length);
  pos_ += length;
  return s;
}

void ColaBWriter::word(const std::string& text) {
  if (!out_.empty())
    out_ += ' ';
  out_ += text;
}

void ColaBWriter::unsignedValue(std::uint64_t value, int bits) {
  if (bits != 8 && bits != 16 && bits != 32 && bits != 64) {
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "no CoLa-B field is " + std::to_string(bits) + " bits wide");
  }
  checkFits(value, bits);
  // The binary part follows the command words after one space.
  if (!out_.empty() && out_.back() != ' ' && binary_start_ == std::string::npos)
    out_ += ' ';
  if (binary_start_ == std::string::npos)
    binary_start_ = out_.size();
  for (int shift = bits - 8; shift >= 0; shift -= 8)
    out_.push_back(static_cast<char>((value >> shift) & 0xFF));
}

void ColaBWriter::signedValue(std::int32_t value) {
  unsignedValue(static_cast<std::uint32_t>(value), 32);
}

void ColaBWriter::floatValue(float value) {
  unsignedValue(floatBits(value), 32);
}

void ColaBWriter::label(const std::string& text, std::size_t width) {
  if (text.size() != width) {
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "CoLa-B label '" + text + "' must be " + std::to_string(width) + " characters");
  }
  characters(text);
}

void ColaBWriter::characters(const std::string& text) {
  if (binary_start_ == std::string::npos) {
    out_ += ' ';
    binary_start_ = out_.size();
  }
  out_ += text;
}

std::unique_ptr<FieldReader> makeReader(Protocol protocol, std::string payload) {
  if (protocol == Protocol::COLA_A)
    return std::make_unique<ColaAReader>(std::move(payload));
  return std::make_unique<ColaBReader>(std::move(payload));
}

std::unique_ptr<FieldWriter> makeWriter(Protocol protocol) {
  if (protocol == Protocol::COLA_A)
    return std::make_unique<ColaAWriter>();
  return std::make_unique<ColaBWriter>();
}

}  // namespace lms111
}  // namespace dormant_tree_modeling
