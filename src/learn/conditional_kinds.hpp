#pragma once
// Internal: what conditional_model.cpp needs of each kind to read its model file.

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ontime/learn/conditional_model.hpp"

namespace ontime::detail {

using ModelJson = nlohmann::ordered_json;

struct ModelHeader {
  std::vector<std::string> feature_names;
  double step_seconds = 1;
  Steps horizon = 1;
  std::size_t rows = 0, worlds = 0;
};

// Reads the members of a model file's "parameters" object; `fail` throws InputError at a place
// under "parameters".
class ParameterReader {
 public:
  ParameterReader(const ModelJson& parameters, std::string source)
      : parameters_(parameters), source_(std::move(source)) {}
  std::string text(const std::string& key) const;
  double real(const std::string& key) const;
  std::vector<double> reals(const std::string& key, std::size_t size) const;  // size 0: any length >= 1
  std::vector<int> whole_numbers(const std::string& key) const;
  [[noreturn]] void fail(const std::string& key, const std::string& rule) const;

 private:
  const ModelJson& at(const std::string& key) const;
  const ModelJson& parameters_;
  std::string source_;
};

std::unique_ptr<ConditionalTimeModel> read_pooled_model(const ParameterReader& reader, ModelHeader header);
std::unique_ptr<ConditionalTimeModel> read_hazard_model(const ParameterReader& reader, ModelHeader header);
std::unique_ptr<ConditionalTimeModel> read_boosted_model(const ParameterReader& reader, ModelHeader header);

}  // namespace ontime::detail
