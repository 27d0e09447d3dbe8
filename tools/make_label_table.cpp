// make_label_table: produces a program's resource label table from one capture of it and the
// program's oracle. This stands in for the once-per-asset human annotation of VIPER: each mesh key
// gets the class its draws most often had (a wheel shared by cars and buses gets one label, as an
// annotator would give it). Ground-truth nodes then use only the table, never the oracle.
#include "viper/ground_truth/oracle_labels.h"

#include <iostream>
#include <map>
#include <string>

int main(int argc, char** argv) {
  const bool help = argc == 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h");
  if (argc != 4 || help) {
    std::cerr << "usage: make_label_table CAPTURE.vcap ORACLE.txt OUT_LABELS.yaml\n"
                 "  Labels every mesh key of the capture with the majority class of its draws in the oracle.\n";
    return help ? 0 : 2;
  }
  try {
    size_t frames = 0;
    const viper::LabelTable table = viper::labelTableFromOracle(argv[1], argv[2], &frames);
    table.save(argv[3]);
    std::cout << "make_label_table: " << table.size() << " mesh labels from " << frames << " frames -> " << argv[3]
              << "\n";
  } catch (const std::exception& e) {
    std::cerr << "make_label_table: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
