#include "vehicles.h"

#include "classes.h"

#include <string>
#include <vector>

namespace viper {
namespace world {

namespace {
const Vec3 kPaint{0.85f, 0.85f, 0.85f};  // tinted per vehicle by the renderer
const Vec3 kGlass{0.08f, 0.1f, 0.13f};
const Vec3 kTire{0.06f, 0.06f, 0.06f};
const Vec3 kHead{0.95f, 0.95f, 0.85f};
const Vec3 kTail{0.8f, 0.05f, 0.05f};

struct Dims {
  float front, rear, width, sill, belt, roof;  // x of front/rear, width, z of sill/beltline/roof
  float cab_front, cab_rear;                   // x extent of the cabin at the roof
  float wheel_r;
};

Mat4 wheelAt(float x, float y, float r) {
  (void)r;
  return translation({x, y, 0}) * rotationX(kPi * 0.5f);
}

MeshData wheels(const std::vector<Vec3>& centers, float r, float w, int segments) {
  MeshData m;
  for (Vec3 c : centers) {
    m.addCylinder(wheelAt(c.x, c.y + w * 0.5f, r) * translation({0, r, 0}) * Mat4(), r, w,
                  segments, kTire);
    if (segments > 8)  // hub cap on the outer face
      m.addCylinder(wheelAt(c.x, c.y + (c.y > 0 ? w * 0.5f + 0.01f : -w * 0.5f + 0.01f), r) *
                        translation({0, r, 0}),
                    r * 0.5f, 0.02f, 8, {0.6f, 0.6f, 0.62f});
  }
  return m;
}

MeshData body(const Dims& d, bool detailed) {
  MeshData m;
  float hw = d.width * 0.5f;
  if (detailed) {
    std::vector<Vec3> lower{{d.rear, 0, d.sill},          {d.front - 0.15f, 0, d.sill},
                            {d.front, 0, d.sill + 0.15f}, {d.front, 0, d.belt - 0.1f},
                            {d.front - 0.2f, 0, d.belt},  {d.rear + 0.1f, 0, d.belt},
                            {d.rear, 0, d.belt - 0.1f}};
    m.addExtrusion(Mat4(), lower, hw, kPaint);
    for (float x : {d.front + 0.05f, d.rear - 0.05f})
      m.addBox(translation({x, 0, d.sill + 0.12f}), {0.08f, hw, 0.1f}, {0.15f, 0.15f, 0.15f});
    for (float y : {hw + 0.08f, -hw - 0.08f})
      m.addBox(translation({d.cab_front + 0.1f, y, d.belt + 0.1f}), {0.06f, 0.08f, 0.06f}, kPaint);
  } else {
    m.addBox(translation({(d.front + d.rear) * 0.5f, 0, (d.sill + d.belt) * 0.5f}),
             {(d.front - d.rear) * 0.5f, hw, (d.belt - d.sill) * 0.5f}, kPaint);
  }
  // Cabin roof (a trapezoid; the glass band is the windows part).
  float base_front = d.cab_front + 0.35f * (d.roof - d.belt), roof_front = d.cab_front;
  std::vector<Vec3> roof{{d.cab_rear - 0.1f, 0, d.roof - 0.08f}, {roof_front, 0, d.roof - 0.08f},
                         {roof_front, 0, d.roof}, {d.cab_rear - 0.1f, 0, d.roof}};
  m.addExtrusion(Mat4(), roof, hw - 0.05f, kPaint);
  (void)base_front;
  return m;
}

MeshData windows(const Dims& d, bool detailed) {
  MeshData m;
  float slope = d.cab_front < d.front - 0.3f ? 0.5f : 0.05f;
  std::vector<Vec3> cab{{d.cab_rear - 0.1f, 0, d.belt},
                        {std::min(d.front - 0.05f, d.cab_front + slope * (d.roof - d.belt)), 0, d.belt},
                        {d.cab_front, 0, d.roof - 0.08f},
                        {d.cab_rear, 0, d.roof - 0.08f}};
  if (!detailed) cab = {{d.cab_rear, 0, d.belt}, {d.cab_front + 0.2f, 0, d.belt},
                        {d.cab_front + 0.2f, 0, d.roof - 0.08f}, {d.cab_rear, 0, d.roof - 0.08f}};
  m.addExtrusion(Mat4(), cab, d.width * 0.5f - 0.08f, kGlass);
  if (detailed) {  // window pillars
    for (float y : {d.width * 0.5f - 0.06f, -d.width * 0.5f + 0.06f})
      m.addBox(translation({(d.cab_front + d.cab_rear) * 0.5f, y, (d.belt + d.roof) * 0.5f}),
               {0.05f, 0.03f, (d.roof - d.belt) * 0.5f}, kPaint);
  }
  return m;
}

MeshData lights(float x, float z, float half_span, Vec3 color, bool facing_front) {
  MeshData m;
  float dx = facing_front ? 0.02f : -0.02f;
  for (float y : {half_span, -half_span})
    m.addBox(translation({x + dx, y, z}), {0.04f, 0.16f, 0.07f}, color);
  return m;
}

void addParts(MeshLibrary& lib, VehicleModel& v, const std::string& name, const Dims& d) {
  v.body[0] = lib.add(name + "_body_lod0", v.class_id, body(d, true));
  v.body[1] = lib.add(name + "_body_lod1", v.class_id, body(d, false));
  v.windows[0] = lib.add(name + "_windows_lod0", v.class_id, windows(d, true));
  v.windows[1] = lib.add(name + "_windows_lod1", v.class_id, windows(d, false));
  v.taillights[0] = v.taillights[1] =
      lib.add(name + "_taillights", v.class_id, lights(d.rear, d.belt - 0.15f, d.width * 0.38f, kTail, false));
}
}  // namespace

std::array<VehicleModel, kVehicleKinds> buildVehicleModels(MeshLibrary& lib) {
  std::array<VehicleModel, kVehicleKinds> models;
  // Car and van share the front axle position, front end, wheels and headlights.
  const Dims car{2.25f, -2.15f, 1.8f, 0.25f, 0.95f, 1.45f, 0.6f, -1.5f, 0.33f};
  const Dims van{2.25f, -2.65f, 1.95f, 0.3f, 1.1f, 2.1f, 1.2f, -2.55f, 0.33f};
  const Dims bus{5.6f, -5.6f, 2.5f, 0.35f, 1.2f, 3.1f, 5.5f, -5.5f, 0.5f};
  const Dims truck{4.0f, -4.0f, 2.45f, 0.45f, 1.5f, 3.3f, 3.9f, 2.2f, 0.5f};
  const std::vector<Vec3> std_axles{{1.4f, 0.72f, 0}, {1.4f, -0.72f, 0}, {-1.4f, 0.72f, 0},
                                    {-1.4f, -0.72f, 0}};
  const std::vector<Vec3> heavy_axles{{3.2f, 1.0f, 0}, {3.2f, -1.0f, 0}, {-2.8f, 1.0f, 0},
                                      {-2.8f, -1.0f, 0}};
  int std_wheels[2] = {lib.add("wheels_std_lod0", -1, wheels(std_axles, 0.33f, 0.22f, 14)),
                       lib.add("wheels_std_lod1", -1, wheels(std_axles, 0.33f, 0.22f, 6))};
  int heavy_wheels[2] = {lib.add("wheels_heavy_lod0", -1, wheels(heavy_axles, 0.5f, 0.32f, 14)),
                         lib.add("wheels_heavy_lod1", -1, wheels(heavy_axles, 0.5f, 0.32f, 6))};
  int std_head = lib.add("headlights_std", -1, lights(2.25f, 0.75f, 0.6f, kHead, true));

  struct Spec { VehicleKind kind; uint8_t cls; const char* name; Dims d; bool heavy; };
  const Spec specs[4] = {{kKindCar, kCar, "car", car, false},
                         {kKindVan, kVan, "van", van, false},
                         {kKindBus, kBus, "bus", bus, true},
                         {kKindTruck, kTruck, "truck", truck, true}};
  for (const Spec& s : specs) {
    VehicleModel& v = models[s.kind];
    v.class_id = s.cls;
    v.length_m = s.d.front - s.d.rear;
    v.width_m = s.d.width;
    v.height_m = s.d.roof;
    addParts(lib, v, s.name, s.d);
    for (int l = 0; l < 2; ++l) v.wheels[l] = s.heavy ? heavy_wheels[l] : std_wheels[l];
    if (s.heavy) {
      int h = lib.add(std::string(s.name) + "_headlights", s.cls,
                      lights(s.d.front, 0.9f, s.d.width * 0.38f, kHead, true));
      v.headlights[0] = v.headlights[1] = h;
    } else {
      v.headlights[0] = v.headlights[1] = std_head;
    }
  }
  // Truck: a cargo box behind the cab.
  {
    MeshData cargo = lib.at(models[kKindTruck].body[0]).data;
    cargo.addBox(translation({-1.0f, 0, 2.0f}), {2.9f, 1.25f, 1.5f}, {0.75f, 0.75f, 0.78f});
    MeshData cargo1 = lib.at(models[kKindTruck].body[1]).data;
    cargo1.addBox(translation({-1.0f, 0, 2.0f}), {2.9f, 1.25f, 1.5f}, {0.75f, 0.75f, 0.78f});
    models[kKindTruck].body[0] = lib.add("truck_cargo_body_lod0", kTruck, std::move(cargo));
    models[kKindTruck].body[1] = lib.add("truck_cargo_body_lod1", kTruck, std::move(cargo1));
  }
  // Motorcycle: frame, tank and seat; two wheels; one headlight.
  VehicleModel& m = models[kKindMotorcycle];
  m.class_id = kMotorcycle;
  m.length_m = 2.1f;
  m.width_m = 0.7f;
  m.height_m = 1.2f;
  for (int l = 0; l < 2; ++l) {
    MeshData b;
    b.addBox(translation({0, 0, 0.55f}), {0.6f, 0.12f, 0.12f}, {0.2f, 0.2f, 0.22f});
    b.addBox(translation({0.2f, 0, 0.78f}), {0.3f, 0.17f, 0.12f}, kPaint);
    b.addBox(translation({-0.35f, 0, 0.78f}), {0.3f, 0.15f, 0.06f}, {0.1f, 0.1f, 0.1f});
    b.addBox(translation({0.75f, 0, 0.85f}) * rotationY(-0.35f), {0.04f, 0.04f, 0.35f},
             {0.5f, 0.5f, 0.5f});
    if (l == 0) b.addBox(translation({0.72f, 0, 1.15f}), {0.03f, 0.35f, 0.02f}, {0.3f, 0.3f, 0.3f});
    m.body[l] = lib.add(std::string("motorcycle_body_lod") + char('0' + l), kMotorcycle, b);
    std::vector<Vec3> axles{{0.75f, 0.06f, 0}, {-0.7f, 0.06f, 0}};
    m.wheels[l] = lib.add(std::string("motorcycle_wheels_lod") + char('0' + l), kMotorcycle,
                          wheels(axles, 0.32f, 0.12f, l == 0 ? 14 : 6));
    MeshData glass;
    glass.addBox(translation({0.85f, 0, 1.2f}) * rotationY(-0.3f), {0.01f, 0.18f, 0.1f}, kGlass);
    m.windows[l] = lib.add(std::string("motorcycle_windows_lod") + char('0' + l), kMotorcycle, glass);
  }
  MeshData head;
  head.addBox(translation({0.85f, 0, 1.0f}), {0.05f, 0.08f, 0.06f}, kHead);
  m.headlights[0] = m.headlights[1] = lib.add("motorcycle_headlight", kMotorcycle, head);
  MeshData tail;
  tail.addBox(translation({-0.8f, 0, 0.75f}), {0.03f, 0.07f, 0.04f}, kTail);
  m.taillights[0] = m.taillights[1] = lib.add("motorcycle_taillight", kMotorcycle, tail);
  return models;
}

}  // namespace world
}  // namespace viper
