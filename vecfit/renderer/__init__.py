"""The differentiable renderer: a Scene (vecfit.scene) packed into the compiled core's
arrays, and render(), a torch autograd function over the core."""
