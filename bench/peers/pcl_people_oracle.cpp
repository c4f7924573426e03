// The thesis authors' C++ (PCL 1.13 people module) as an oracle and a speed peer.
//
//   pcl_people_oracle classify MODEL.yaml IMAGE.ppm WINDOWS.txt
//       One line per window "height xc yc" (pixels) in WINDOWS.txt: prints
//       pcl::people::PersonClassifier<pcl::RGB>::evaluate(height, xc, yc, image), %.9f.
//   pcl_people_oracle detect MODEL.yaml CLOUD.pcd A B C D FX FY CX CY VOXEL REPEAT [RANGE]
//       Runs GroundBasedPeopleDetectionApp<PointXYZRGBA>::compute on the organised
//       cloud REPEAT times (ground plane a b c d and intrinsics given; min/max height
//       1.4/2.3 m; depth range RANGE m, default 6.5 as Table 5.1 of seed 000, PCL's
//       own default is 50); prints the CPU
//       time of each call ("cpu_ms <t>", this thread's CPU clock) and the clusters
//       of the last call ("person <confidence> <height> <x> <y> <z>").
//
// Build: see README.md in this folder.

#include <pcl/io/pcd_io.h>
#include <pcl/people/ground_based_people_detection_app.h>
#include <pcl/people/person_classifier.h>
#include <pcl/point_types.h>

#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace {

bool read_ppm(const std::string& path, pcl::PointCloud<pcl::RGB>::Ptr& image) {
  std::ifstream in(path, std::ios::binary);
  std::string magic;
  int width = 0, height = 0, maxval = 0;
  in >> magic >> width >> height >> maxval;
  in.get();  // the single whitespace after the header
  if (!in || magic != "P6" || maxval != 255 || width <= 0 || height <= 0) {
    std::cerr << path << ": expected a binary PPM (P6, maxval 255)\n";
    return false;
  }
  std::vector<unsigned char> data(static_cast<std::size_t>(width) * height * 3);
  in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(data.size()));
  if (!in) {
    std::cerr << path << ": truncated PPM\n";
    return false;
  }
  image->width = width;
  image->height = height;
  image->points.resize(static_cast<std::size_t>(width) * height);
  for (std::size_t i = 0; i < image->points.size(); ++i) {
    image->points[i].r = data[3 * i];
    image->points[i].g = data[3 * i + 1];
    image->points[i].b = data[3 * i + 2];
  }
  return true;
}

double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

int classify(const std::string& model, const std::string& image_path, const std::string& windows) {
  pcl::people::PersonClassifier<pcl::RGB> classifier;
  if (!classifier.loadSVMFromFile(model)) return 2;
  pcl::PointCloud<pcl::RGB>::Ptr image(new pcl::PointCloud<pcl::RGB>);
  if (!read_ppm(image_path, image)) return 2;
  std::ifstream in(windows);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    float height, xc, yc;
    if (!(fields >> height >> xc >> yc)) continue;
    std::printf("%.9f\n", classifier.evaluate(height, xc, yc, image));
  }
  return 0;
}

int detect(int argc, char** argv) {
  using PointT = pcl::PointXYZRGBA;
  pcl::people::PersonClassifier<pcl::RGB> classifier;
  if (!classifier.loadSVMFromFile(argv[2])) return 2;
  pcl::PointCloud<PointT>::Ptr input(new pcl::PointCloud<PointT>);
  if (pcl::io::loadPCDFile<PointT>(argv[3], *input) < 0) return 2;
  Eigen::VectorXf ground(4);
  ground << std::stof(argv[4]), std::stof(argv[5]), std::stof(argv[6]), std::stof(argv[7]);
  Eigen::Matrix3f intrinsics;
  intrinsics << std::stof(argv[8]), 0, std::stof(argv[10]), 0, std::stof(argv[9]),
      std::stof(argv[11]), 0, 0, 1;
  const float voxel = std::stof(argv[12]);
  const int repeat = std::stoi(argv[13]);
  const float range = argc > 14 ? std::stof(argv[14]) : 6.5f;
  std::vector<pcl::people::PersonCluster<PointT>> clusters;
  for (int k = 0; k < repeat; ++k) {
    // A fresh app and copy of the cloud per call: compute() modifies both.
    pcl::PointCloud<PointT>::Ptr cloud(new pcl::PointCloud<PointT>(*input));
    Eigen::VectorXf plane = ground;
    pcl::people::GroundBasedPeopleDetectionApp<PointT> app;
    app.setVoxelSize(voxel);
    app.setIntrinsics(intrinsics);
    app.setClassifier(classifier);
    app.setPersonClusterLimits(1.4f, 2.3f, 0.1f, 8.0f);
    app.setFOV(0.0f, range);
    app.setGround(plane);
    app.setInputCloud(cloud);
    clusters.clear();
    const double start = thread_cpu_ms();
    app.compute(clusters);
    std::printf("cpu_ms %.4f\n", thread_cpu_ms() - start);
  }
  for (auto& c : clusters) {
    const Eigen::Vector3f t = c.getTCenter();
    std::printf("person %.6f %.4f %.4f %.4f %.4f\n", c.getPersonConfidence(), c.getHeight(),
                t(0), t(1), t(2));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "classify" && argc == 5) return classify(argv[2], argv[3], argv[4]);
  if (mode == "detect" && (argc == 14 || argc == 15)) return detect(argc, argv);
  std::cerr << "usage: " << argv[0] << " classify MODEL.yaml IMAGE.ppm WINDOWS.txt\n"
            << "       " << argv[0]
            << " detect MODEL.yaml CLOUD.pcd A B C D FX FY CX CY VOXEL REPEAT [RANGE]\n";
  return 2;
}
