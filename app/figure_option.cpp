// SPDX-License-Identifier: Apache-2.0
#include "figure_option.hpp"

#include <filesystem>

namespace settle::app {

int parse_png_option(const ParsedArgs& args, std::optional<FigurePath>& out) {
  out.reset();
  const auto png = args.text("--png");
  if (!png) return -1;
  const std::filesystem::path p{*png};
  if (p.extension() != ".png" || p.stem().empty()) {
    return report_bad_request({"bad_png", "--png", "--png: the figure's file name must end in .png"}, args.json());
  }
  out = FigurePath{p.parent_path().empty() ? std::string{"."} : p.parent_path().string(), p.stem().string(), *png};
  return -1;
}

}  // namespace settle::app
