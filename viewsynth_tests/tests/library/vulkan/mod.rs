/// GL against Vulkan for the cyclopean gather pass.
mod cyclopean;
/// Every pass's parameter blocks, GL against Vulkan per capability, steady state, freed images.
mod passes;
/// GL against Vulkan for refocus, every method and convention.
mod refocus;
