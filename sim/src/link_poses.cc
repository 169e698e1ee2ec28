#include "link_poses.h"

namespace leglab::sim {

std::vector<Eigen::Isometry3d> LinkPoses(const std::vector<LinkDescription>& links,
                                         const LegAngles& q_rad) {
  std::vector<Eigen::Isometry3d> poses(links.size(), Eigen::Isometry3d::Identity());
  for (std::size_t i = 1; i < links.size(); ++i) {
    const LinkDescription& link = links[i];
    poses[i] = poses[link.parent] * ToEigen(link.origin);
    if (link.joint >= 0) {
      poses[i].rotate(Eigen::AngleAxisd(q_rad[link.joint], ToEigen(link.axis)));
    }
  }
  return poses;
}

}  // namespace leglab::sim
