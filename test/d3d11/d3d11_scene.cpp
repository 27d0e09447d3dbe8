// d3d11_scene: a small Direct3D 11 program (Windows, built with mingw-w64, run under wine, whose
// wined3d turns it into OpenGL) that the OpenGL capture layer is tested on. It draws a ground slab
// and a few spinning cubes with a depth buffer, in the conventions of the Direct3D SDK samples:
// a left-handed world (the camera looks along +z), row vectors (HLSL `mul(v, M)`), matrices
// transposed on upload into a constant buffer with named members, depth 0..1. It knows nothing of
// capture; --oracle writes the true answers for tests in viper's oracle format (docs/oracle_format.md),
// in the conventions a capture with `handedness: left` records (OpenGL's, the world mirrored in z).
// Its world is y-up, not the oracle's z-up, so the oracle's camera_pose is written as the identity
// (nothing that reads this program's oracle uses it).
#define WIN32_LEAN_AND_MEAN
#include <windows.h>
#include <d3d11.h>
#include <d3dcompiler.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

// Row-major 4x4, row-vector convention (v' = v M), as DirectXMath's XMMATRIX.
struct Mat {
  float m[4][4];
};

Mat identity() {
  Mat r{};
  for (int i = 0; i < 4; ++i) r.m[i][i] = 1.0f;
  return r;
}

Mat mul(const Mat& a, const Mat& b) {
  Mat r{};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) r.m[i][j] += a.m[i][k] * b.m[k][j];
  return r;
}

Mat transpose(const Mat& a) {
  Mat r{};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = a.m[j][i];
  return r;
}

Mat scaling(float x, float y, float z) {
  Mat r = identity();
  r.m[0][0] = x, r.m[1][1] = y, r.m[2][2] = z;
  return r;
}

Mat translation(float x, float y, float z) {
  Mat r = identity();
  r.m[3][0] = x, r.m[3][1] = y, r.m[3][2] = z;
  return r;
}

// XMMatrixRotationY: rotates +z towards +x for positive angles in the left-handed world.
Mat rotationY(float a) {
  Mat r = identity();
  r.m[0][0] = std::cos(a), r.m[0][2] = -std::sin(a);
  r.m[2][0] = std::sin(a), r.m[2][2] = std::cos(a);
  return r;
}

// XMMatrixLookAtLH.
Mat lookAtLH(const float eye[3], const float at[3], const float up[3]) {
  float z[3] = {at[0] - eye[0], at[1] - eye[1], at[2] - eye[2]};
  const float zl = std::sqrt(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]);
  for (float& c : z) c /= zl;
  float x[3] = {up[1] * z[2] - up[2] * z[1], up[2] * z[0] - up[0] * z[2], up[0] * z[1] - up[1] * z[0]};
  const float xl = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
  for (float& c : x) c /= xl;
  const float y[3] = {z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]};
  Mat r = identity();
  for (int i = 0; i < 3; ++i) r.m[i][0] = x[i], r.m[i][1] = y[i], r.m[i][2] = z[i];
  r.m[3][0] = -(x[0] * eye[0] + x[1] * eye[1] + x[2] * eye[2]);
  r.m[3][1] = -(y[0] * eye[0] + y[1] * eye[1] + y[2] * eye[2]);
  r.m[3][2] = -(z[0] * eye[0] + z[1] * eye[1] + z[2] * eye[2]);
  return r;
}

// XMMatrixPerspectiveFovLH: depth 0 at the near plane, 1 at the far plane.
Mat perspectiveFovLH(float fov_y, float aspect, float near_m, float far_m) {
  const float h = 1.0f / std::tan(0.5f * fov_y), range = far_m / (far_m - near_m);
  Mat r{};
  r.m[0][0] = h / aspect, r.m[1][1] = h;
  r.m[2][2] = range, r.m[2][3] = 1.0f;
  r.m[3][2] = -range * near_m;
  return r;
}

// The column-vector matrix in OpenGL's conventions of the world mirrored in z (F = diag(1,1,-1,1)):
// F M^T F for world and view. The projection becomes Dz P^T F, Dz mapping depth 0..1 to GL's -1..1.
Mat glMirrored(const Mat& row_vector) {
  const Mat f = scaling(1, 1, -1);
  return mul(mul(f, transpose(row_vector)), f);
}

Mat glProjection(const Mat& row_vector) {
  Mat dz = identity();
  dz.m[2][2] = 2.0f, dz.m[2][3] = -1.0f;
  return mul(mul(dz, transpose(row_vector)), scaling(1, 1, -1));
}

// "%.9g" x 16, column-major (the order glUniformMatrix4fv reads).
std::string glText(const Mat& column_vector) {
  std::string s;
  char buf[32];
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      std::snprintf(buf, sizeof buf, " %.9g", column_vector.m[r][c]);
      s += buf;
    }
  return s;
}

const char kShaders[] = R"(
cbuffer Transforms : register(b0) {
  float4x4 world;
  float4x4 view;
  float4x4 projection;
  float4 tint;
};
struct VsOut {
  float4 position : SV_Position;
  float3 color : COLOR;
};
VsOut vs_main(float3 position : POSITION) {
  VsOut o;
  o.position = mul(mul(mul(float4(position, 1.0), world), view), projection);
  o.color = tint.rgb * (0.55 + 0.45 * (position.y + 0.5));
  return o;
}
float4 ps_main(VsOut i) : SV_Target { return float4(i.color, 1.0); }
)";

// The constant buffer's layout (transposed matrices: HLSL's default column_major packing).
struct Transforms {
  Mat world, view, projection;
  float tint[4];
};

// A unit cube around the origin: 8 corners, 12 triangles, clockwise seen from outside (D3D's front).
const float kCubeVertices[8][3] = {{-0.5f, -0.5f, -0.5f}, {0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, -0.5f},
                                   {-0.5f, 0.5f, -0.5f},  {-0.5f, -0.5f, 0.5f}, {0.5f, -0.5f, 0.5f},
                                   {0.5f, 0.5f, 0.5f},    {-0.5f, 0.5f, 0.5f}};
const uint16_t kCubeIndices[36] = {0, 3, 2, 0, 2, 1,  // -z
                                   4, 5, 6, 4, 6, 7,  // +z
                                   0, 4, 7, 0, 7, 3,  // -x
                                   1, 2, 6, 1, 6, 5,  // +x
                                   3, 7, 6, 3, 6, 2,  // +y
                                   0, 1, 5, 0, 5, 4};  // -y

struct Object {
  const char* part;
  uint32_t class_id;  // config/viper_classes.csv
  float x, y, z, size_x, size_y, size_z, spin_rad_per_s;
  float tint[3];
};

const Object kObjects[] = {
    {"ground", 1, 0.0f, -0.55f, 6.0f, 12.0f, 0.1f, 14.0f, 0.0f, {0.35f, 0.38f, 0.35f}},
    {"cube_a", 2, -1.6f, 0.0f, 5.0f, 1.0f, 1.0f, 1.0f, 0.9f, {0.85f, 0.25f, 0.2f}},
    {"cube_b", 2, 0.2f, 0.25f, 7.0f, 1.5f, 1.5f, 1.5f, -0.6f, {0.2f, 0.45f, 0.85f}},
    {"cube_c", 2, 1.9f, -0.1f, 4.2f, 0.8f, 0.8f, 0.8f, 1.4f, {0.9f, 0.8f, 0.2f}},
};

struct Options {
  int frames = 5, width = 320, height = 240;
  double fps = 10.0;
  std::string oracle;
};

void fail(const char* what, HRESULT hr) {
  std::fprintf(stderr, "d3d11_scene: %s failed (hr 0x%08lx)\n", what, static_cast<unsigned long>(hr));
  std::exit(1);
}

LRESULT CALLBACK windowProc(HWND window, UINT message, WPARAM w, LPARAM l) {
  if (message == WM_DESTROY) PostQuitMessage(0);
  return DefWindowProcW(window, message, w, l);
}

ID3DBlob* compile(const char* entry, const char* target) {
  ID3DBlob *code = nullptr, *errors = nullptr;
  const HRESULT hr = D3DCompile(kShaders, sizeof kShaders - 1, "d3d11_scene.hlsl", nullptr, nullptr, entry, target,
                                D3DCOMPILE_ENABLE_STRICTNESS, 0, &code, &errors);
  if (FAILED(hr)) {
    std::fprintf(stderr, "d3d11_scene: D3DCompile(%s, %s): %s\n", entry, target,
                 errors ? static_cast<const char*>(errors->GetBufferPointer()) : "no message");
    std::exit(1);
  }
  if (errors) errors->Release();
  return code;
}

int run(const Options& o) {
  HINSTANCE instance = GetModuleHandleW(nullptr);
  WNDCLASSW window_class{};
  window_class.lpfnWndProc = windowProc;
  window_class.hInstance = instance;
  window_class.lpszClassName = L"d3d11_scene";
  RegisterClassW(&window_class);
  RECT rect = {0, 0, o.width, o.height};
  AdjustWindowRect(&rect, WS_OVERLAPPEDWINDOW, FALSE);
  HWND window = CreateWindowW(L"d3d11_scene", L"d3d11_scene", WS_OVERLAPPEDWINDOW, 0, 0, rect.right - rect.left,
                              rect.bottom - rect.top, nullptr, nullptr, instance, nullptr);
  if (!window) fail("CreateWindow", HRESULT_FROM_WIN32(GetLastError()));
  ShowWindow(window, SW_SHOW);

  DXGI_SWAP_CHAIN_DESC sd{};
  sd.BufferCount = 1;
  sd.BufferDesc.Width = o.width;
  sd.BufferDesc.Height = o.height;
  sd.BufferDesc.Format = DXGI_FORMAT_R8G8B8A8_UNORM;
  sd.BufferUsage = DXGI_USAGE_RENDER_TARGET_OUTPUT;
  sd.OutputWindow = window;
  sd.SampleDesc.Count = 1;
  sd.Windowed = TRUE;
  sd.SwapEffect = DXGI_SWAP_EFFECT_DISCARD;
  const D3D_FEATURE_LEVEL levels[] = {D3D_FEATURE_LEVEL_11_0, D3D_FEATURE_LEVEL_10_1, D3D_FEATURE_LEVEL_10_0};
  IDXGISwapChain* swap_chain = nullptr;
  ID3D11Device* device = nullptr;
  ID3D11DeviceContext* context = nullptr;
  D3D_FEATURE_LEVEL level{};
  HRESULT hr = D3D11CreateDeviceAndSwapChain(nullptr, D3D_DRIVER_TYPE_HARDWARE, nullptr, 0, levels, 3,
                                             D3D11_SDK_VERSION, &sd, &swap_chain, &device, &level, &context);
  if (FAILED(hr)) fail("D3D11CreateDeviceAndSwapChain", hr);
  std::fprintf(stderr, "d3d11_scene: %dx%d, feature level %x\n", o.width, o.height, static_cast<unsigned>(level));

  ID3D11Texture2D* back_buffer = nullptr;
  if (FAILED(hr = swap_chain->GetBuffer(0, __uuidof(ID3D11Texture2D), reinterpret_cast<void**>(&back_buffer))))
    fail("GetBuffer", hr);
  ID3D11RenderTargetView* rtv = nullptr;
  if (FAILED(hr = device->CreateRenderTargetView(back_buffer, nullptr, &rtv))) fail("CreateRenderTargetView", hr);
  D3D11_TEXTURE2D_DESC dd{};
  dd.Width = o.width;
  dd.Height = o.height;
  dd.MipLevels = 1;
  dd.ArraySize = 1;
  dd.Format = DXGI_FORMAT_D24_UNORM_S8_UINT;
  dd.SampleDesc.Count = 1;
  dd.BindFlags = D3D11_BIND_DEPTH_STENCIL;
  ID3D11Texture2D* depth = nullptr;
  ID3D11DepthStencilView* dsv = nullptr;
  if (FAILED(hr = device->CreateTexture2D(&dd, nullptr, &depth))) fail("CreateTexture2D (depth)", hr);
  if (FAILED(hr = device->CreateDepthStencilView(depth, nullptr, &dsv))) fail("CreateDepthStencilView", hr);

  ID3DBlob* vs_code = compile("vs_main", "vs_4_0");
  ID3DBlob* ps_code = compile("ps_main", "ps_4_0");
  ID3D11VertexShader* vs = nullptr;
  ID3D11PixelShader* ps = nullptr;
  if (FAILED(hr = device->CreateVertexShader(vs_code->GetBufferPointer(), vs_code->GetBufferSize(), nullptr, &vs)))
    fail("CreateVertexShader", hr);
  if (FAILED(hr = device->CreatePixelShader(ps_code->GetBufferPointer(), ps_code->GetBufferSize(), nullptr, &ps)))
    fail("CreatePixelShader", hr);
  const D3D11_INPUT_ELEMENT_DESC element = {"POSITION", 0, DXGI_FORMAT_R32G32B32_FLOAT, 0, 0,
                                            D3D11_INPUT_PER_VERTEX_DATA, 0};
  ID3D11InputLayout* layout = nullptr;
  if (FAILED(hr = device->CreateInputLayout(&element, 1, vs_code->GetBufferPointer(), vs_code->GetBufferSize(), &layout)))
    fail("CreateInputLayout", hr);

  D3D11_BUFFER_DESC bd{};
  D3D11_SUBRESOURCE_DATA init{};
  bd.Usage = D3D11_USAGE_IMMUTABLE;
  bd.ByteWidth = sizeof kCubeVertices;
  bd.BindFlags = D3D11_BIND_VERTEX_BUFFER;
  init.pSysMem = kCubeVertices;
  ID3D11Buffer *vertices = nullptr, *indices = nullptr, *constants = nullptr;
  if (FAILED(hr = device->CreateBuffer(&bd, &init, &vertices))) fail("CreateBuffer (vertices)", hr);
  bd.ByteWidth = sizeof kCubeIndices;
  bd.BindFlags = D3D11_BIND_INDEX_BUFFER;
  init.pSysMem = kCubeIndices;
  if (FAILED(hr = device->CreateBuffer(&bd, &init, &indices))) fail("CreateBuffer (indices)", hr);
  bd.Usage = D3D11_USAGE_DYNAMIC;
  bd.ByteWidth = sizeof(Transforms);
  bd.BindFlags = D3D11_BIND_CONSTANT_BUFFER;
  bd.CPUAccessFlags = D3D11_CPU_ACCESS_WRITE;
  if (FAILED(hr = device->CreateBuffer(&bd, nullptr, &constants))) fail("CreateBuffer (constants)", hr);

  FILE* oracle = nullptr;
  if (!o.oracle.empty()) {
    oracle = std::fopen(o.oracle.c_str(), "w");
    if (!oracle) {
      std::fprintf(stderr, "d3d11_scene: cannot write %s\n", o.oracle.c_str());
      return 1;
    }
    // One mesh, mirrored in z as the capture of a left-handed program records it.
    std::fprintf(oracle, "viper_oracle 2\nsize %d %d\nmesh cube 8 12 0\n", o.width, o.height);
    for (const auto& v : kCubeVertices) std::fprintf(oracle, "v %.9g %.9g %.9g\n", v[0], v[1], -v[2]);
    for (int t = 0; t < 12; ++t)
      std::fprintf(oracle, "t %u %u %u\n", kCubeIndices[3 * t], kCubeIndices[3 * t + 1], kCubeIndices[3 * t + 2]);
  }

  const float eye[3] = {0.0f, 2.2f, -1.5f}, at[3] = {0.0f, 0.0f, 6.0f}, up[3] = {0.0f, 1.0f, 0.0f};
  const Mat view = lookAtLH(eye, at, up);
  const Mat projection = perspectiveFovLH(1.0f, static_cast<float>(o.width) / o.height, 0.1f, 100.0f);
  const D3D11_VIEWPORT viewport = {0.0f, 0.0f, static_cast<float>(o.width), static_cast<float>(o.height), 0.0f, 1.0f};
  const UINT stride = sizeof kCubeVertices[0], offset = 0;
  const float clear[4] = {0.55f, 0.7f, 0.9f, 1.0f};
  for (int n = 0; n < o.frames; ++n) {
    MSG message;
    while (PeekMessageW(&message, nullptr, 0, 0, PM_REMOVE)) DispatchMessageW(&message);
    const double time_s = n / o.fps;
    context->OMSetRenderTargets(1, &rtv, dsv);
    context->ClearRenderTargetView(rtv, clear);
    context->ClearDepthStencilView(dsv, D3D11_CLEAR_DEPTH | D3D11_CLEAR_STENCIL, 1.0f, 0);
    context->RSSetViewports(1, &viewport);
    context->IASetInputLayout(layout);
    context->IASetVertexBuffers(0, 1, &vertices, &stride, &offset);
    context->IASetIndexBuffer(indices, DXGI_FORMAT_R16_UINT, 0);
    context->IASetPrimitiveTopology(D3D11_PRIMITIVE_TOPOLOGY_TRIANGLELIST);
    context->VSSetShader(vs, nullptr, 0);
    context->VSSetConstantBuffers(0, 1, &constants);
    context->PSSetShader(ps, nullptr, 0);
    if (oracle)
      std::fprintf(oracle, "frame %d %.17g %zu\nview%s\nprojection%s\ncamera_pose 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n", n,
                   time_s, sizeof kObjects / sizeof kObjects[0], glText(glMirrored(view)).c_str(),
                   glText(glProjection(projection)).c_str());
    uint32_t index = 0;
    for (const Object& object : kObjects) {
      const Mat world = mul(mul(scaling(object.size_x, object.size_y, object.size_z),
                                rotationY(static_cast<float>(object.spin_rad_per_s * time_s))),
                            translation(object.x, object.y, object.z));
      D3D11_MAPPED_SUBRESOURCE mapped;
      if (FAILED(hr = context->Map(constants, 0, D3D11_MAP_WRITE_DISCARD, 0, &mapped))) fail("Map", hr);
      Transforms t{transpose(world), transpose(view), transpose(projection), {object.tint[0], object.tint[1], object.tint[2], 1.0f}};
      std::memcpy(mapped.pData, &t, sizeof t);
      context->Unmap(constants, 0);
      context->DrawIndexed(36, 0, 0);
      if (oracle)
        std::fprintf(oracle, "draw %u %u %u %s cube 0 0\nworld%s\n", index, index, object.class_id, object.part,
                     glText(glMirrored(world)).c_str());
      ++index;
    }
    if (FAILED(hr = swap_chain->Present(0, 0))) fail("Present", hr);
    if (oracle) std::fflush(oracle);
  }
  if (oracle) std::fclose(oracle);
  std::fprintf(stderr, "d3d11_scene: %d frames presented\n", o.frames);
  swap_chain->Release();
  context->Release();
  device->Release();
  DestroyWindow(window);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--frames" && has_value) o.frames = std::atoi(argv[++i]);
    else if (arg == "--width" && has_value) o.width = std::atoi(argv[++i]);
    else if (arg == "--height" && has_value) o.height = std::atoi(argv[++i]);
    else if (arg == "--fps" && has_value) o.fps = std::atof(argv[++i]);
    else if (arg == "--oracle" && has_value) o.oracle = argv[++i];
    else {
      std::fprintf(stderr, "usage: d3d11_scene [--frames N] [--width W] [--height H] [--fps F] [--oracle FILE]\n");
      return 2;
    }
  }
  if (o.frames < 1 || o.width < 16 || o.height < 16 || !(o.fps > 0)) {
    std::fprintf(stderr, "d3d11_scene: --frames >= 1, --width and --height >= 16, --fps > 0\n");
    return 2;
  }
  return run(o);
}
