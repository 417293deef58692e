"""Pictures (PNG): the capability map, one panel per yaw and spin; joint use along a path."""

from service.caches import settle_matplotlib_folder

settle_matplotlib_folder()  # before matplotlib is imported: where it keeps its files

from service.render.joint_use import render_joint_use, render_message  # noqa: E402
from service.render.map_picture import figure_pixels, render_png  # noqa: E402

__all__ = ["figure_pixels", "render_joint_use", "render_message", "render_png"]
