"""The differentiable renderer: the Scene (plain data of torch tensors), its packing into
the compiled core's arrays, and render(), a torch autograd function over the core."""
