// Errors at Penumbra's IO boundary. InputError carries the file and the element (a JSON path
// such as "meshes[2].primitives[0]") so a farm log says exactly what is wrong where.
#pragma once

#include <stdexcept>
#include <string>

namespace penumbra {

/// Bad user input (malformed file, missing file, invalid value). The CLI maps it to exit 2.
class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::string element, const std::string& message)
      : std::runtime_error(compose(file, element, message)),
        m_file(std::move(file)),
        m_element(std::move(element)) {}
  const std::string& file() const { return m_file; }
  const std::string& element() const { return m_element; }

 private:
  static std::string compose(const std::string& file, const std::string& element,
                             const std::string& message) {
    std::string s = file;
    if (!element.empty()) s += (s.empty() ? "" : ": ") + element;
    return s + (s.empty() ? "" : ": ") + message;
  }
  std::string m_file, m_element;
};

}  // namespace penumbra
