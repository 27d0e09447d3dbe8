// make_label_table: produces a program's resource label table from one capture of it and the
// program's oracle. This stands in for the once-per-asset human annotation of VIPER: each mesh key
// gets the class its draws most often had (a wheel shared by cars and buses gets one label, as an
// annotator would give it). Ground-truth nodes then use only the table, never the oracle.
#include "command_line.h"
#include "viper/ground_truth/oracle_labels.h"

#include <iostream>
#include <map>
#include <string>

int main(int argc, char** argv) {
  CLI::App app("Labels every mesh key of the capture with the majority class of its draws in the oracle.",
               "make_label_table");
  std::string capture, oracle, out;
  app.add_option("CAPTURE.vcap", capture, "a capture of one of our programs")->required()->type_name("");
  app.add_option("ORACLE.txt", oracle, "the program's oracle of the same run")->required()->type_name("");
  app.add_option("OUT_LABELS.yaml", out, "the label table to write")->required()->type_name("");
  app.footer("Exit status: 0 written; 1 the capture or oracle cannot be read, or the table cannot be written; 2\n"
             "usage error.");
  if (const auto status = viper_tools::parseCommandLine(app, argc, argv)) return *status;
  try {
    size_t frames = 0;
    const viper::LabelTable table = viper::labelTableFromOracle(capture, oracle, &frames);
    table.save(out);
    std::cout << "make_label_table: " << table.size() << " mesh labels from " << frames << " frames -> " << out
              << "\n";
  } catch (const std::exception& e) {
    std::cerr << "make_label_table: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
