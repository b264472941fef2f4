// Binding numbers of storage images and storage buffers, one text for GL and Vulkan (src/pass/
// mod.rs). GL numbers image units and buffer bindings in namespaces of their own, from 0 (and
// guarantees only 8 of each); Vulkan has one namespace per descriptor set, shared with the
// parameter block (0) and the sampled images (1..=7). So binding k of a kind is k under GL and
// a fixed offset plus k under Vulkan (glslang defines VULKAN).
#ifdef VULKAN
#define STORAGE_IMAGE(k) binding = (8 + (k))
#define STORAGE_BUFFER(k) binding = (12 + (k))
#else
#define STORAGE_IMAGE(k) binding = (k)
#define STORAGE_BUFFER(k) binding = (k)
#endif
