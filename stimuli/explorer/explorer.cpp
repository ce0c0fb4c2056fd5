#include "stimuli/explorer/explorer.h"

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <utility>

#include "renderer/core/technique.h"
#include "renderer/gl/default_framebuffer.h"
#include "renderer/gl/readback.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"
#include "renderer/ui/imgui_window.h"
#include "stimuli/explorer/stimulus_entry.h"

namespace lucent::explorer {
namespace {

ImVec2 project(const Camera& camera, glm::vec3 point, ImVec2 origin, ImVec2 size) {
    const glm::vec4 clip = camera.projection() * camera.view() * glm::vec4(point, 1.f);
    const float w = clip.w > 1e-6f ? clip.w : 1e-6f;
    return {origin.x + (clip.x / w * 0.5f + 0.5f) * size.x,
            origin.y + (0.5f - clip.y / w * 0.5f) * size.y};
}

}  // namespace

Explorer::Explorer(ExplorerSession session, const ExplorerOptions& options)
    : session_(std::move(session)) {
    load_mesh(session_.mesh);
    ui::ImGuiWindowOptions window;
    window.window.width = options.width;
    window.window.height = options.height;
    window.window.visible = options.visible;
    window.window.vsync = false;  // the status bar reports the renderer's own frame time
    window.window.title = "Lucent explorer";
    window.font_pixels = options.font_pixels;
    window_ = std::make_unique<ui::ImGuiWindow>(window);
    ViewInput view;
    view.orbit = [this](float dx, float dy) { orbit(session_, dx, dy); };
    view.move_light = [this](float dx, float dy) {
        try {
            drag_light(session_, dx, dy);
        } catch (const KnobError& e) {
            session_.message = e.what();
        }
    };
    view.zoom = [this](float notches) { zoom(session_, notches); };
    view.key = [this](int key) {
        if (key == GLFW_KEY_SPACE) session_.edited = 1 - session_.edited;  // A/B flip
    };
    input_ = std::make_unique<InputRouter>(window_->glfw(), std::move(view));
    view_ = std::make_unique<ViewRenderer>();
}

Explorer::~Explorer() {
    view_.reset();
    input_.reset();
}

bool Explorer::should_close() const { return glfwWindowShouldClose(window_->glfw()); }

const RenderedSide& Explorer::shown() const {
    return view_->side(session_.side_by_side ? 0 : session_.edited);
}

const RenderedSide& Explorer::side(int index) const { return view_->side(index); }

bool Explorer::ambient_occlusion_pending() const { return view_->bakes().busy(); }

std::optional<WidgetRect> Explorer::widget(const std::string& id) const {
    const auto it = widgets_.find(id);
    if (it == widgets_.end()) return std::nullopt;
    return it->second;
}

void Explorer::view_size(int& width, int& height) const {
    window_->framebuffer_size(width, height);
    if (session_.side_by_side) width = std::max(1, width / 2);
}

void Explorer::load_mesh(const std::string& spec) {
    auto mesh = std::make_shared<const Mesh>(lucent::load_mesh(spec));
    mesh_min_ = glm::vec3(std::numeric_limits<float>::max());
    mesh_max_ = -mesh_min_;
    for (const glm::vec3& p : mesh->positions) {
        mesh_min_ = glm::min(mesh_min_, p);
        mesh_max_ = glm::max(mesh_max_, p);
    }
    mesh_ = std::move(mesh);
    session_.mesh = spec;
}

std::size_t Explorer::save_image(const std::filesystem::path& path) {
    if (!is_supported_image_path(path))
        throw std::invalid_argument(
            "image file: '" + path.string() +
            "' has an unsupported extension (accepted: .exr, .png, .tif)");
    int width = 0, height = 0;
    view_size(width, height);
    // The path of `lucent render`: request -> build_scene -> render_image -> write_image.
    Scene scene = build_scene(render_request(session_, session_.edited, width, height));
    if (!session_.default_view())
        scene = make_scene(scene.mesh, find_technique(scene.technique), scene.values,
                           width, height, view_direction(session_));
    gl::FrameExecutor executor;  // its own: disk-cached AO as `lucent render` uses
    const RenderedImage rendered = render_image_counted(executor, scene);
    write_image(path, rendered.image);
    return rendered.non_finite_pixels;
}

std::string Explorer::add_to_stimulus_set(const std::filesystem::path& config,
                                          const std::string& id) {
    StimulusEntry entry;
    entry.id = id;
    entry.technique = session_.current().technique();
    entry.mesh = session_.mesh;
    entry.values = session_.current().values();
    view_size(entry.width, entry.height);
    return append_stimulus(config, entry);
}

void Explorer::reload_shaders() {
#ifdef LUCENT_RENDERER_SOURCE_DIR
    // Developer mode reads shaders from the source tree unless told otherwise.
    if (!std::getenv("LUCENT_SHADER_DIR"))
        setenv("LUCENT_SHADER_DIR", LUCENT_RENDERER_SOURCE_DIR, 0);
#endif
    view_->drop_executors();
    const char* dir = std::getenv("LUCENT_SHADER_DIR");
    session_.message = std::string("shaders reloaded from ") + (dir ? dir : "the binary");
}

void Explorer::animate(float seconds) {
    if (session_.auto_rotate)
        session_.yaw_degrees = std::fmod(
            session_.yaw_degrees + session_.rotate_degrees_per_second * seconds, 360.f);
    if (session_.random_light_motion) {
        // A damped random walk of the light's angular velocity (pixels of "drag" per
        // second).
        std::normal_distribution<float> kick(0.f, 40.f);
        light_velocity_ = 0.9f * light_velocity_ +
                          glm::vec2(kick(light_motion_), kick(light_motion_)) * seconds;
        drag_light(session_, light_velocity_.x * seconds * 60.f,
                   light_velocity_.y * seconds * 60.f);
    }
}

void Explorer::handle(const PanelRequests& requests) {
    try {
        if (requests.load_mesh && !session_.mesh_path_field.empty()) {
            load_mesh(session_.mesh_path_field);
            session_.message = "loaded " + session_.mesh;
        }
        if (requests.save_image) {
            const std::size_t non_finite = save_image(session_.save_image_path);
            session_.message = "saved " + session_.save_image_path;
            if (non_finite > 0)
                session_.message += " (warning: " + std::to_string(non_finite) +
                                    " pixels had NaN or Inf values, written as 0 or the "
                                    "largest float)";
        }
        if (requests.add_to_stimulus_set) {
            const std::string id =
                add_to_stimulus_set(session_.stimulus_config, session_.stimulus_id);
            session_.message =
                "added stimulus '" + id + "' to " + session_.stimulus_config;
        }
        if (requests.reload_shaders) reload_shaders();
        if (requests.rebake_ambient_occlusion) {
            view_->bakes().forget_all();
            view_->drop_executors();  // executors keep AO streams; fetch the new bake
        }
    } catch (const std::exception& e) {
        session_.message = e.what();
    }
}

PanelInfo Explorer::panel_info() const {
    PanelInfo info;
    info.faces = mesh_->face_count();
    info.vertices = mesh_->vertex_count();
    const RenderedSide& side = shown();
    if (side.valid) {
        info.near_plane = side.scene.camera.near_plane;
        info.far_plane = side.scene.camera.far_plane;
        info.plan = &side.plan;
        info.timings = &side.timings;
        info.refinement = side.refinement_status();
    }
    info.frame_times = stats_.summary();
    info.baking = view_->bakes().busy();
    info.bake_progress = view_->bakes().progress();
    info.bake_error = view_->bakes().error();
    info.buffer_message = view_->buffer_message();
    return info;
}

void Explorer::draw_view() {
    ImDrawList* draw = ImGui::GetBackgroundDrawList();
    float x = 0.f;
    for (int index : view_->shown()) {
        const RenderedSide& side = view_->side(index);
        if (!side.valid || !side.texture.id()) continue;
        const ImVec2 origin(x, 0.f),
            size(float(side.texture_width), float(side.texture_height));
        draw->AddImage(ui::imgui_texture(side.texture), origin,
                       ImVec2(x + size.x, size.y));
        if (view_->shown().size() > 1)
            draw->AddText(ImVec2(x + size.x - 40.f, 8.f), IM_COL32(255, 255, 255, 255),
                          index == 0 ? "A" : "B");
        const Camera& camera = side.scene.camera;
        if (session_.show_axes) {
            const glm::vec3 c = side.scene.bounds.centre;
            const float r = side.scene.bounds.radius;
            const ImU32 colours[3] = {IM_COL32(230, 60, 60, 255),
                                      IM_COL32(60, 200, 60, 255),
                                      IM_COL32(70, 110, 240, 255)};
            for (int axis = 0; axis < 3; ++axis) {
                glm::vec3 end = c;
                end[axis] += r;
                draw->AddLine(project(camera, c, origin, size),
                              project(camera, end, origin, size), colours[axis], 2.f);
            }
        }
        if (session_.show_bounds) {
            for (int edge = 0; edge < 12; ++edge) {
                // Edge `edge` runs along axis edge/4 between corners differing in that
                // axis.
                const int axis = edge / 4, a = (axis + 1) % 3, b = (axis + 2) % 3;
                glm::vec3 p = mesh_min_, q;
                p[a] = (edge & 1) ? mesh_max_[a] : mesh_min_[a];
                p[b] = (edge & 2) ? mesh_max_[b] : mesh_min_[b];
                q = p;
                q[axis] = mesh_max_[axis];
                draw->AddLine(project(camera, p, origin, size),
                              project(camera, q, origin, size),
                              IM_COL32(255, 220, 90, 200), 1.f);
            }
        }
        x += size.x;
    }
}

void Explorer::step() {
    const double start = glfwGetTime();
    const float seconds =
        last_frame_end_ < 0.0 ? 0.f : static_cast<float>(start - last_frame_end_);
    // ImGuiWindow::begin_frame(), split so the router's pointer state reaches ImGui
    // between the back end's NewFrame (which polls GLFW) and ImGui::NewFrame.
    glfwPollEvents();
    input_->run_script_step();
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    input_->update_imgui_pointer();
    ImGui::NewFrame();

    animate(seconds);
    handle(draw_panels(session_, panel_info(), widgets_));
    int width = 0, height = 0;
    window_->framebuffer_size(width, height);
    try {
        view_->render(session_, mesh_, width, height);
    } catch (const std::exception& e) {
        session_.message =
            e.what();  // e.g. a shader that no longer compiles after reload
    }
    draw_view();

    gl::clear_default_framebuffer(width, height, glm::vec3(0.0f));
    window_->render_imgui();
    if (!screenshot_.empty()) {
        const std::vector<std::uint8_t> pixels =
            gl::read_framebuffer_rgba8(width, height);
        Image image(width,
                    height);  // GL rows bottom first; the window's bytes, unchanged
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const std::uint8_t* p =
                    &pixels[(static_cast<std::size_t>(height - 1 - y) * width + x) * 4];
                image.set(x, y, glm::vec4(p[0], p[1], p[2], 255.f) / 255.f);
            }
        ImageWriteOptions linear;
        linear.linear = true;
        std::filesystem::path path = std::exchange(screenshot_, {});
        write_image(path, image, linear);
    }
    window_->swap();
    const double end = glfwGetTime();
    last_frame_ms_ = (end - start) * 1000.0;
    stats_.add(end, last_frame_ms_);
    last_frame_end_ = end;
}

}  // namespace lucent::explorer
