"""Pictures (PNG): the capability map, one panel per yaw and spin; joint use along a path."""

from service.render.joint_use import render_joint_use, render_message
from service.render.map_picture import figure_pixels, render_png

__all__ = ["figure_pixels", "render_joint_use", "render_message", "render_png"]
