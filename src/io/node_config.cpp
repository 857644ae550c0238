#include "dormant_tree_modeling/common/config_table.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"

namespace dormant_tree_modeling {
namespace io {

namespace {

ConfigTable<CloudPublisherConfig> makeTable() {
  using C = CloudPublisherConfig;
  ConfigTable<C> t("cloud file publisher parameter", "");
  t.add("file", &C::file, "The cloud to publish (.pcd, .ply or .xyz); required.")
      .add("frame_id", &C::frame_id, "Frame of the published cloud.")
      .add("rate_hz", &C::rate_hz, 0.0, 1000.0, "Republish rate; 0: once, latched.")
      .formerly("rate");
  return t;
}

}  // namespace

const ConfigTable<CloudPublisherConfig>& cloudPublisherConfigTable() {
  static const ConfigTable<CloudPublisherConfig> table = makeTable();
  return table;
}

void CloudPublisherConfig::validate() const {
  cloudPublisherConfigTable().check(*this);
  if (file.empty())
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "cloud file publisher parameter file is required (a .pcd, .ply or .xyz)");
}

}  // namespace io
}  // namespace dormant_tree_modeling
