#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "dormant_tree_modeling/lms111/cola.h"

namespace dormant_tree_modeling {
namespace lms111 {

/// @brief Reads the fields of one telegram payload in order. Both protocols start with the
/// command type and name as ASCII words ("sSN LMDscandata"); after them CoLa-A writes every
/// field as a space-separated token and CoLa-B as a fixed-width big-endian value. Every read
/// throws Error PARSE_ERROR naming the field and its position when the payload does not hold
/// what is asked for, so one structural walk serves both protocols.
class FieldReader {
 public:
  virtual ~FieldReader() = default;
  /// @brief The next space-delimited ASCII word (command type, command name; CoLa-A: any field).
  virtual std::string word(const char* field) = 0;
  /// @brief Unsigned value of `bits` bits (8, 16, 32). CoLa-A: hex, or decimal with '+'.
  virtual std::uint64_t unsignedValue(const char* field, int bits = 32) = 0;
  /// @brief Signed 32-bit value (CoLa-A: two's-complement hex or signed decimal).
  virtual std::int32_t signedValue(const char* field) = 0;
  /// @brief IEEE-754 single precision (CoLa-A: 8 hex digits).
  virtual float floatValue(const char* field) = 0;
  /// @brief A channel or event name: a token in CoLa-A, exactly `width` bytes in CoLa-B.
  virtual std::string label(const char* field, std::size_t width) = 0;
  /// @brief Exactly `length` characters (a string may hold spaces).
  virtual std::string characters(const char* field, std::size_t length) = 0;
  /// @brief Whether every field was read.
  virtual bool atEnd() const = 0;
  /// @brief Characters (CoLa-A) or bytes (CoLa-B) consumed so far.
  virtual std::size_t position() const = 0;

 protected:
  [[noreturn]] void fail(const char* field, std::size_t position, const std::string& what) const;
};

/// @brief CoLa-A: space-separated tokens, numbers hexadecimal without prefix or decimal with a
/// sign (docs/protocols.md).
class ColaAReader : public FieldReader {
 public:
  explicit ColaAReader(std::string text) : text_(std::move(text)) {}
  std::string word(const char* field) override { return token(field); }
  /// @brief The next token, as text.
  std::string token(const char* field);
  std::uint64_t unsignedValue(const char* field, int bits = 32) override;
  std::int32_t signedValue(const char* field) override;
  float floatValue(const char* field) override;
  std::string label(const char* field, std::size_t) override { return token(field); }
  std::string characters(const char* field, std::size_t length) override;
  bool atEnd() const override;
  std::size_t position() const override { return pos_; }

 private:
  std::string text_;
  std::size_t pos_ = 0;
};

/// @brief CoLa-B: after the command words, big-endian fixed-width binary fields.
class ColaBReader : public FieldReader {
 public:
  explicit ColaBReader(std::string payload) : data_(std::move(payload)) {}
  std::string word(const char* field) override;
  std::uint64_t unsignedValue(const char* field, int bits = 32) override;
  std::int32_t signedValue(const char* field) override;
  float floatValue(const char* field) override;
  std::string label(const char* field, std::size_t width) override;
  std::string characters(const char* field, std::size_t length) override;
  bool atEnd() const override { return pos_ >= data_.size(); }
  std::size_t position() const override { return pos_; }

 private:
  std::uint64_t bigEndian(const char* field, int bytes);
  std::string data_;
  std::size_t pos_ = 0;
};

/// @brief Writes fields in the order a FieldReader reads them back.
class FieldWriter {
 public:
  virtual ~FieldWriter() = default;
  virtual void word(const std::string& text) = 0;
  /// @throws Error INVALID_ARGUMENT when the value does not fit in `bits` bits
  virtual void unsignedValue(std::uint64_t value, int bits = 32) = 0;
  virtual void signedValue(std::int32_t value) = 0;
  virtual void floatValue(float value) = 0;
  /// @throws Error INVALID_ARGUMENT for a CoLa-B label that is not `width` bytes long
  virtual void label(const std::string& text, std::size_t width) = 0;
  virtual void characters(const std::string& text) = 0;
  /// @brief The payload written so far.
  const std::string& payload() const { return out_; }

 protected:
  std::string out_;
};

/// @brief CoLa-A writer: numbers as upper-case hex tokens, signed values as two's complement.
class ColaAWriter : public FieldWriter {
 public:
  void word(const std::string& text) override;
  void unsignedValue(std::uint64_t value, int bits = 32) override;
  void signedValue(std::int32_t value) override;
  void floatValue(float value) override;
  void label(const std::string& text, std::size_t) override { word(text); }
  void characters(const std::string& text) override;
};

/// @brief CoLa-B writer: command words followed by one space, then big-endian binary.
class ColaBWriter : public FieldWriter {
 public:
  void word(const std::string& text) override;
  void unsignedValue(std::uint64_t value, int bits = 32) override;
  void signedValue(std::int32_t value) override;
  void floatValue(float value) override;
  void label(const std::string& text, std::size_t width) override;
  void characters(const std::string& text) override;

 private:
  std::size_t binary_start_ = std::string::npos;  // where the binary part begins
};

/// @brief A reader of one payload in the protocol.
std::unique_ptr<FieldReader> makeReader(Protocol protocol, std::string payload);
/// @brief An empty writer for the protocol.
std::unique_ptr<FieldWriter> makeWriter(Protocol protocol);

}  // namespace lms111
}  // namespace dormant_tree_modeling
