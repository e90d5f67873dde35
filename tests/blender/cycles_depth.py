"""Cycles set up to render depth exactly, for the Blender tests (run inside Blender's Python).

One sample on the CPU, nothing but the camera rays: the Z pass holds the depth of sample 0,
which Cycles (3.0+) aims at the pixel centre whatever the filter (integrate_camera_sample:
filter_u = filter_v = 0.5 for sample 0), through the filter's importance table. That table has
an even size (1024), so its centre falls between two entries: the sample lands half a table step
off the centre, table width / 2046 in x and in y. The box filter's width is fixed at 1 px
(blender/sync.cpp ignores filter_width for it): 1/2046 = 0.00049 px; Blackman-Harris 1.5 px (the
default) ~0.0005 px; a 0.01 px Gaussian (table width 0.03 px, mass near the middle) ~3e-6 px. All
lie within the 2^-8 px zcheck allows; the Gaussian leaves the least.
"""


def set_up_depth_render(scene, resolution=None, percentage=100, position_pass=False):
    """Cycles, one sample at the pixel centre, the Z pass (and, if asked, Position) written as
    32-bit multilayer EXR; `resolution` (x, y) if given, else the scene's own."""
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 1
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.max_bounces = 0
    scene.cycles.pixel_filter_type = "GAUSSIAN"
    scene.cycles.filter_width = 0.01
    scene.cycles.seed = 0
    scene.render.film_transparent = True
    if resolution is not None:
        scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = percentage
    scene.render.use_border = False
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    layer = scene.view_layers[0]
    layer.use_pass_z = True
    layer.use_pass_position = position_pass
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
