// make_label_table: produces a program's resource label table from one capture of it and the
// program's oracle. This stands in for the once-per-asset human annotation of VIPER: each mesh key
// gets the class its draws most often had (a wheel shared by cars and buses gets one label, as an
// annotator would give it). Ground-truth nodes then use only the table, never the oracle.
#include "viper/capture/capture_stream.h"
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
    const viper::Oracle oracle = viper::readOracle(argv[2]);
    std::map<uint64_t, const viper::OracleFrame*> by_number;
    for (const auto& f : oracle.frames) by_number[f.number] = &f;

    viper::CaptureReader reader(argv[1]);
    viper::CaptureFrame frame;
    viper::OracleLabeler labeler;
    while (reader.next(frame) == viper::CaptureReader::Status::kFrame) {
      auto it = by_number.find(frame.number);
      if (it != by_number.end()) labeler.add(frame, *it->second);
    }
    if (labeler.framesAdded() == 0) {
      std::cerr << "make_label_table: no frame of " << argv[1] << " is in the oracle " << argv[2] << "\n";
      return 1;
    }
    const viper::LabelTable table = labeler.table();
    table.save(argv[3]);
    std::cout << "make_label_table: " << table.size() << " mesh labels from " << labeler.framesAdded() << " frames -> " << argv[3]
              << "\n";
  } catch (const std::exception& e) {
    std::cerr << "make_label_table: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
