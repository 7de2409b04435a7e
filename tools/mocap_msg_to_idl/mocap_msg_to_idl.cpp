// mocap_msg_to_idl: converts a ROS 2 .msg file to IDL as rosidl_adapter does. Run by
// mocap_generate_messages for the .msg files of a message package; useful by hand to see the
// IDL a .msg file becomes.
//
//   mocap_msg_to_idl --package my_msgs [--known Other]... [-I <idl dir>]... Thing.msg Thing.idl
//
// --known names the package's own types (they may not be converted yet); every other message
// type a field uses must be <dir>/<pkg>/msg/<Type>.idl under an -I directory. An output of "-"
// is the standard output. Errors are one line, "<file>:<line>: <reason>", and exit 1.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "mocap_msg_to_idl/msg_to_idl.hpp"

namespace {

const char* kUsage =
    "usage: mocap_msg_to_idl --package <pkg> [--known <Type>]... [-I <idl dir>]... <in.msg> "
    "<out.idl>";

int convert(int argc, char** argv) {
  std::string package;
  std::set<std::string> known;
  std::vector<std::filesystem::path> include_dirs;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--package" && has_value)
      package = argv[++i];
    else if (arg == "--known" && has_value)
      known.insert(argv[++i]);
    else if (arg == "-I" && has_value)
      include_dirs.emplace_back(argv[++i]);
    else if (arg == "-h" || arg == "--help") {
      std::cout << kUsage << "\n";
      return 0;
    } else if (!arg.empty() && arg[0] == '-' && arg != "-") {
      std::cerr << "mocap_msg_to_idl: unknown option " << arg << "\n" << kUsage << "\n";
      return 2;
    } else {
      files.push_back(arg);
    }
  }
  if (package.empty() || files.size() != 2) {
    std::cerr << kUsage << "\n";
    return 2;
  }
  const std::filesystem::path input = files[0];
  std::ifstream in(input, std::ios::binary);
  if (!in) {
    std::cerr << input.string() << ": cannot read\n";
    return 1;
  }
  std::stringstream text;
  text << in.rdbuf();

  try {
    const mocap::MsgSpecification msg =
        mocap::parse_msg(package, input.stem().string(), text.str(), input.string());
    for (const auto& field : msg.fields) {
      const auto& type = field.type;
      if (type.is_primitive() || (type.package == package && known.count(type.name))) continue;
      bool found = false;
      for (const auto& dir : include_dirs)
        found = found || std::filesystem::exists(dir / type.package / "msg" / (type.name + ".idl"));
      if (!found) {
        std::string where = type.package == package ? "not a type of " + package : "";
        for (const auto& dir : include_dirs)
          where += (where.empty() ? "no " : ", no ") +
                   (dir / type.package / "msg" / (type.name + ".idl")).string();
        const bool ros1_header = type.name == "Header" && type.package != "std_msgs";
        std::cerr << input.string() << ":" << field.line << ": unknown type " << type.package << "/"
                  << type.name << " (" << where << ")"
                  << (ros1_header ? "; ROS 2 writes std_msgs/Header" : "") << "\n";
        return 1;
      }
    }
    const std::string idl = mocap::msg_to_idl(msg, package + "/msg/" + input.filename().string());
    if (files[1] == "-") {
      std::cout << idl;
      return 0;
    }
    const std::filesystem::path output = files[1];
    if (output.has_parent_path()) std::filesystem::create_directories(output.parent_path());
    std::ofstream out(output, std::ios::binary);
    out << idl;
    if (!out) {
      std::cerr << output.string() << ": cannot write\n";
      return 1;
    }
  } catch (const mocap::MsgError& error) {
    std::cerr << error.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return convert(argc, argv); }
