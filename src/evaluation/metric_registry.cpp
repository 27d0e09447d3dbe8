// The registered metrics. A metric is one file in src/evaluation/metrics/ that defines its
// factory; registering it is one declaration and one entry below (its place is its place in the
// report).
#include "viper/evaluation/metric.h"

namespace viper {

std::unique_ptr<Metric> makeSemanticIouMetric(const MetricContext&);
std::unique_ptr<Metric> makeSemanticIiouMetric(const MetricContext&);
std::unique_ptr<Metric> makeInstanceApMetric(const MetricContext&);
std::unique_ptr<Metric> makeDenseFlowMetric(const MetricContext&);
std::unique_ptr<Metric> makeSparseFlowMetric(const MetricContext&);
std::unique_ptr<Metric> makeOdometryMetric(const MetricContext&);

const std::vector<MetricFactory>& registeredMetrics() {
  static const std::vector<MetricFactory> metrics = {makeSemanticIouMetric, makeInstanceApMetric,
                                                     makeDenseFlowMetric,   makeSparseFlowMetric,
                                                     makeOdometryMetric,    makeSemanticIiouMetric};
  return metrics;
}

}  // namespace viper
