// Writes the seeds of the packet doors with the product's own encoders (and the OpenIGTLink
// library's, as a client packs them): fuzz/corpus/{udp_packet,igtl,surface_binary}/.
// `fuzz_packet_seeds <corpus folder>`.
#include "device/udp_packet.hpp"
#include "ports/surface_binary.hpp"

#include <igtlPositionMessage.h>
#include <igtlTransformMessage.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace {

void write(const std::string& path, const std::uint8_t* bytes, std::size_t size) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes), static_cast<std::streamsize>(size));
}

template <class Message>
void write_message(const std::string& path, Message& message) {
  message.Pack();
  write(path, static_cast<const std::uint8_t*>(message.GetPackPointer()), message.GetPackSize());
}

void write_udp(const std::string& folder) {
  using namespace tissue::host::udp;
  PosePacket pose;
  pose.sequence = 7;
  pose.send_time_s = 1.5;
  pose.pose.position_m = {0.01, 0.02, -0.003};
  pose.pose.mode = tissue::ToolMode::probe;
  const auto pose_bytes = encode_pose(pose);
  write(folder + "/pose", pose_bytes.data(), pose_bytes.size());
  ForcePacket force;
  force.sequence = 3;
  force.force_n = {0.0, 0.5, -1.25};
  force.watchdog_scale = 1.0;
  force.ack_sequence = 7;
  const auto force_bytes = encode_force(force);
  write(folder + "/force", force_bytes.data(), force_bytes.size());
}

void write_igtl(const std::string& folder) {
  igtl::TransformMessage::Pointer transform = igtl::TransformMessage::New();
  transform->SetDeviceName("ProbeToTissue");
  igtl::Matrix4x4 matrix;
  igtl::IdentityMatrix(matrix);
  matrix[0][3] = 10.0F;
  matrix[2][3] = -3.0F;
  transform->SetMatrix(matrix);
  write_message(folder + "/transform_probe", *transform);
  transform->SetDeviceName("ScalpelToTissue");
  write_message(folder + "/transform_scalpel", *transform);
  igtl::PositionMessage::Pointer position = igtl::PositionMessage::New();
  position->SetDeviceName("ProbeToTissue");
  position->SetPackType(igtl::PositionMessage::ALL);
  position->SetPosition(1.0F, 2.0F, 3.0F);
  position->SetQuaternion(0.0F, 0.0F, 0.0F, 1.0F);
  write_message(folder + "/position_probe", *position);
}

void write_surface(const std::string& folder) {
  using namespace tissue::ports;
  std::vector<std::uint8_t> bytes;
  const auto with_selector = [&](std::uint8_t selector, const std::string& name) {
    bytes.insert(bytes.begin(), selector);
    write(folder + "/" + name, bytes.data(), bytes.size());
  };
  SurfaceMesh mesh;
  mesh.positions_m = {0, 0, 0, 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01};
  mesh.triangles = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  mesh.cut_triangle_count = 1;
  encode(mesh, bytes);
  with_selector(0, "mesh");
  SurfaceEmbedding embedding;
  embedding.revision = 2;
  embedding.node_count = 4;
  embedding.point_nodes = {0, 1, 2, 3, 1, 2, 3, 0, 2, 3, 0, 1};
  embedding.point_weights = {1, 0, 0, 0, 0.5, 0.5, 0, 0, 0.25, 0.25, 0.25, 0.25};
  embedding.triangles = {0, 1, 2};
  encode(embedding, bytes);
  with_selector(1, "embedding");
  SurfaceNodes nodes;
  nodes.revision = 2;
  nodes.positions_m = mesh.positions_m;
  encode(nodes, bytes);
  with_selector(2, "nodes");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <corpus folder>\n", argv[0]);
    return 2;
  }
  const std::string corpus = argv[1];
  write_udp(corpus + "/udp_packet");
  write_igtl(corpus + "/igtl");
  write_surface(corpus + "/surface_binary");
  return 0;
}
