"""A minimal Vulkan client (ctypes over libvulkan) that asks RADV what its compiler, ACO,
made of one full-screen graphics pipeline: registers, spills, scratch, waves per SIMD,
instructions (VK_KHR_pipeline_executable_properties).

Why ctypes and no binding package: thirty structures suffice, and the client runs as
a child process (`python vulkan_stats.py`, which imports nothing of implc) (gpu_stats.py), because
RADV reads RADV_FORCE_FAMILY (a "null" device: no GPU needed) and the loader reads
VK_ICD_FILENAMES when the instance is made, so those variables are set in the child's
environment, never in the caller's; and a driver that crashes takes only the child down.
The child reads JSON from stdin, {"vertex": hex, "fragments": [hex, ...]} (SPIR-V words as
hex), and prints {"device": name, "stats": [{statistic: value} per fragment]} or
{"error": why}.
"""

from __future__ import annotations

import ctypes as C
import json
import sys
from collections.abc import Sequence
from typing import Any

u32, u64, f32, p = C.c_uint32, C.c_uint64, C.c_float, C.c_void_p
Handle = C.c_void_p  # dispatchable and (on 64-bit) non-dispatchable handles alike


def _struct(name: str, fields: Sequence[tuple[str, Any]]) -> type[C.Structure]:
    """A ctypes structure from (name, type) pairs (the Vulkan headers' layouts)."""
    return type(name, (C.Structure,), {"_fields_": list(fields)})


S = [("sType", u32), ("pNext", p)]  # every create-info's head
AppInfo = _struct("AppInfo", S + [("pApplicationName", C.c_char_p), ("appVersion", u32),
                                  ("pEngineName", C.c_char_p), ("engineVersion", u32),
                                  ("apiVersion", u32)])
InstanceInfo = _struct("InstanceInfo", S + [
    ("flags", u32), ("pApplicationInfo", C.POINTER(AppInfo)), ("layers", u32), ("ppLayers", p),
    ("extensions", u32), ("ppExtensions", C.POINTER(C.c_char_p))])
QueueInfo = _struct("QueueInfo", S + [("flags", u32), ("family", u32), ("count", u32),
                                      ("pPriorities", C.POINTER(f32))])
ExecutableFeatures = _struct("ExecutableFeatures", S + [("pipelineExecutableInfo", u32)])
DeviceInfo = _struct("DeviceInfo", S + [
    ("flags", u32), ("queueInfos", u32), ("pQueueInfos", C.POINTER(QueueInfo)),
    ("layers", u32), ("ppLayers", p), ("extensions", u32),
    ("ppExtensions", C.POINTER(C.c_char_p)), ("pFeatures", p)])
ModuleInfo = _struct("ModuleInfo", S + [("flags", u32), ("codeSize", C.c_size_t),
                                        ("pCode", C.POINTER(u32))])
StageInfo = _struct("StageInfo", S + [("flags", u32), ("stage", u32), ("module", Handle),
                                      ("pName", C.c_char_p), ("pSpecialization", p)])
VertexInput = _struct("VertexInput", S + [("flags", u32), ("nb", u32), ("pb", p), ("na", u32),
                                          ("pa", p)])
Assembly = _struct("Assembly", S + [("flags", u32), ("topology", u32), ("restart", u32)])
ViewportState = _struct("ViewportState", S + [("flags", u32), ("viewports", u32), ("pv", p),
                                              ("scissors", u32), ("ps", p)])
Raster = _struct("Raster", S + [
    ("flags", u32), ("depthClamp", u32), ("discard", u32), ("polygonMode", u32),
    ("cullMode", u32), ("frontFace", u32), ("depthBias", u32), ("biasConstant", f32),
    ("biasClamp", f32), ("biasSlope", f32), ("lineWidth", f32)])
Multisample = _struct("Multisample", S + [
    ("flags", u32), ("samples", u32), ("sampleShading", u32), ("minSampleShading", f32),
    ("pSampleMask", p), ("alphaToCoverage", u32), ("alphaToOne", u32)])
BlendAttachment = _struct("BlendAttachment", [(n, u32) for n in (
    "enable", "srcColor", "dstColor", "colorOp", "srcAlpha", "dstAlpha", "alphaOp", "mask")])
Blend = _struct("Blend", S + [("flags", u32), ("logicOpEnable", u32), ("logicOp", u32),
                              ("attachments", u32), ("pAttachments", C.POINTER(BlendAttachment)),
                              ("constants", f32 * 4)])
Dynamic = _struct("Dynamic", S + [("flags", u32), ("count", u32), ("pStates", C.POINTER(u32))])
SetBinding = _struct("SetBinding", [("binding", u32), ("type", u32), ("count", u32),
                                    ("stages", u32), ("pSamplers", p)])
SetLayoutInfo = _struct("SetLayoutInfo", S + [("flags", u32), ("count", u32),
                                              ("pBindings", C.POINTER(SetBinding))])
LayoutInfo = _struct("LayoutInfo", S + [("flags", u32), ("sets", u32),
                                        ("pSets", C.POINTER(Handle)), ("ranges", u32),
                                        ("pRanges", p)])
Attachment = _struct("Attachment", [(n, u32) for n in (
    "flags", "format", "samples", "loadOp", "storeOp", "stencilLoadOp", "stencilStoreOp",
    "initialLayout", "finalLayout")])
AttachmentRef = _struct("AttachmentRef", [("attachment", u32), ("layout", u32)])
Subpass = _struct("Subpass", [
    ("flags", u32), ("bindPoint", u32), ("inputs", u32), ("pInputs", p), ("colors", u32),
    ("pColors", C.POINTER(AttachmentRef)), ("pResolves", p), ("pDepth", p),
    ("preserves", u32), ("pPreserves", p)])
RenderPassInfo = _struct("RenderPassInfo", S + [
    ("flags", u32), ("attachments", u32), ("pAttachments", C.POINTER(Attachment)),
    ("subpasses", u32), ("pSubpasses", C.POINTER(Subpass)), ("dependencies", u32),
    ("pDependencies", p)])
PipelineInfo = _struct("PipelineInfo", S + [
    ("flags", u32), ("stages", u32), ("pStages", C.POINTER(StageInfo)),
    ("pVertexInput", C.POINTER(VertexInput)), ("pAssembly", C.POINTER(Assembly)),
    ("pTessellation", p), ("pViewport", C.POINTER(ViewportState)),
    ("pRaster", C.POINTER(Raster)), ("pMultisample", C.POINTER(Multisample)),
    ("pDepthStencil", p), ("pBlend", C.POINTER(Blend)), ("pDynamic", C.POINTER(Dynamic)),
    ("layout", Handle), ("renderPass", Handle), ("subpass", u32), ("basePipeline", Handle),
    ("baseIndex", C.c_int32)])
PipelineKHR = _struct("PipelineKHR", S + [("pipeline", Handle)])
ExecutableProperties = _struct("ExecutableProperties", S + [
    ("stages", u32), ("name", C.c_char * 256), ("description", C.c_char * 256),
    ("subgroupSize", u32)])
ExecutableInfo = _struct("ExecutableInfo", S + [("pipeline", Handle), ("index", u32)])
Value = type("Value", (C.Union,), {"_fields_": [("b32", u32), ("i64", C.c_int64),
                                                ("u64", u64), ("f64", C.c_double)]})
Statistic = _struct("Statistic", S + [("name", C.c_char * 256), ("description", C.c_char * 256),
                                      ("format", u32), ("value", Value)])
DeviceProperties = _struct("DeviceProperties", [
    ("apiVersion", u32), ("driverVersion", u32), ("vendorID", u32), ("deviceID", u32),
    ("deviceType", u32), ("deviceName", C.c_char * 256), ("rest", C.c_byte * 1024)])

# VkStructureType values used (vulkan_core.h)
APPLICATION_INFO, INSTANCE, QUEUE, DEVICE, MODULE, STAGE = 0, 1, 2, 3, 16, 18
VERTEX_INPUT, ASSEMBLY, VIEWPORT, RASTER, MULTISAMPLE, BLEND, DYNAMIC = 19, 20, 22, 23, 24, 26, 27
GRAPHICS_PIPELINE, PIPELINE_LAYOUT, SET_LAYOUT, RENDER_PASS = 28, 30, 32, 38
EXECUTABLE_FEATURES, PIPELINE_INFO_KHR = 1000269000, 1000269001
EXECUTABLE_PROPERTIES, EXECUTABLE_INFO, STATISTIC = 1000269002, 1000269003, 1000269004
CAPTURE_STATISTICS = 0x40  # VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR
VERTEX_BIT, FRAGMENT_BIT, ALL_GRAPHICS = 0x01, 0x10, 0x1F
RGBA32F, UNIFORM_BUFFER = 109, 6
OUTPUTS = 2  # colour and aux (every program's two render targets)


class VulkanError(RuntimeError):
    """A Vulkan call failed (its name and VkResult)."""


def _check(result: int, call: str) -> None:
    if result != 0:
        raise VulkanError(f"{call} returned VkResult {result}")


class Client:
    """One instance and one device with pipeline-executable statistics enabled."""

    def __init__(self) -> None:
        self.vk = C.CDLL("libvulkan.so.1")
        vk = self.vk
        for name in ("vkCreateInstance", "vkEnumeratePhysicalDevices", "vkCreateDevice",
                     "vkCreateShaderModule", "vkCreateDescriptorSetLayout",
                     "vkCreatePipelineLayout", "vkCreateRenderPass", "vkCreateGraphicsPipelines"):
            getattr(vk, name).restype = C.c_int32
        vk.vkGetDeviceProcAddr.restype = p
        vk.vkGetDeviceProcAddr.argtypes = [Handle, C.c_char_p]
        app = AppInfo(APPLICATION_INFO, None, b"implc", 1, b"implc", 1, (1 << 22) | (2 << 12))
        ext = (C.c_char_p * 1)(b"VK_KHR_get_physical_device_properties2")
        info = InstanceInfo(INSTANCE, None, 0, C.pointer(app), 0, None, 1, ext)
        self.instance = Handle()
        _check(vk.vkCreateInstance(C.byref(info), None, C.byref(self.instance)),
               "vkCreateInstance")
        count = u32(0)
        vk.vkEnumeratePhysicalDevices(self.instance, C.byref(count), None)
        if count.value == 0:
            raise VulkanError("no Vulkan device (RADV made no null device for this family)")
        physical = (Handle * count.value)()
        vk.vkEnumeratePhysicalDevices(self.instance, C.byref(count), physical)
        props = DeviceProperties()
        vk.vkGetPhysicalDeviceProperties(Handle(physical[0]), C.byref(props))
        self.name = props.deviceName.decode()
        priority = f32(1.0)
        queue = QueueInfo(QUEUE, None, 0, 0, 1, C.pointer(priority))
        features = ExecutableFeatures(EXECUTABLE_FEATURES, None, 1)
        dev_ext = (C.c_char_p * 1)(b"VK_KHR_pipeline_executable_properties")
        dinfo = DeviceInfo(DEVICE, C.cast(C.pointer(features), p), 0, 1, C.pointer(queue), 0,
                           None, 1, dev_ext, None)
        self.device = Handle()
        _check(vk.vkCreateDevice(Handle(physical[0]), C.byref(dinfo), None,
                                 C.byref(self.device)), "vkCreateDevice")
        proto = C.CFUNCTYPE(C.c_int32, Handle, p, C.POINTER(u32), p)
        self.executables = proto(self._proc(b"vkGetPipelineExecutablePropertiesKHR"))
        self.statistics = proto(self._proc(b"vkGetPipelineExecutableStatisticsKHR"))
        self.layout, self.render_pass = self._layout(), self._render_pass()

    def _proc(self, name: bytes) -> int:
        address = self.vk.vkGetDeviceProcAddr(self.device, name)
        if not address:
            raise VulkanError(f"the device has no {name.decode()}")
        return int(address)

    def _create(self, call: str, info: Any) -> Handle:
        handle = Handle()
        _check(getattr(self.vk, call)(self.device, C.byref(info), None, C.byref(handle)), call)
        return handle

    def _layout(self) -> Handle:
        """Set 0, binding 0: the uniform block glslang gives a program's uniforms (HLSL's
        $Globals, GLSL's default uniform block)."""
        binding = SetBinding(0, UNIFORM_BUFFER, 1, ALL_GRAPHICS, None)
        set_layout = self._create("vkCreateDescriptorSetLayout",
                                  SetLayoutInfo(SET_LAYOUT, None, 0, 1, C.pointer(binding)))
        self._set = (Handle * 1)(set_layout)
        return self._create("vkCreatePipelineLayout",
                            LayoutInfo(PIPELINE_LAYOUT, None, 0, 1, self._set, 0, None))

    def _render_pass(self) -> Handle:
        """One subpass writing the program's two float render targets."""
        attachments = (Attachment * OUTPUTS)(*[Attachment(0, RGBA32F, 1, 2, 0, 2, 1, 0, 2)
                                               for _ in range(OUTPUTS)])
        refs = (AttachmentRef * OUTPUTS)(*[AttachmentRef(i, 2) for i in range(OUTPUTS)])
        subpass = Subpass(0, 0, 0, None, OUTPUTS, refs, None, None, 0, None)
        return self._create("vkCreateRenderPass", RenderPassInfo(
            RENDER_PASS, None, 0, OUTPUTS, attachments, 1, C.pointer(subpass), 0, None))

    def _module(self, words: bytes) -> Handle:
        code = (u32 * (len(words) // 4)).from_buffer_copy(words)
        return self._create("vkCreateShaderModule", ModuleInfo(MODULE, None, 0, len(words), code))

    def fragment_stats(self, vertex: bytes, fragment: bytes) -> dict[str, float]:
        """The fragment executable's statistics of a pipeline of these two SPIR-V stages."""
        stages = (StageInfo * 2)(
            StageInfo(STAGE, None, 0, VERTEX_BIT, self._module(vertex), b"main", None),
            StageInfo(STAGE, None, 0, FRAGMENT_BIT, self._module(fragment), b"main", None))
        blends = (BlendAttachment * OUTPUTS)(*[BlendAttachment(0, 1, 0, 0, 1, 0, 0, 0xF)
                                               for _ in range(OUTPUTS)])
        dynamic = (u32 * 2)(0, 1)  # viewport and scissor
        info = PipelineInfo(
            GRAPHICS_PIPELINE, None, CAPTURE_STATISTICS, 2, stages,
            C.pointer(VertexInput(VERTEX_INPUT, None, 0, 0, None, 0, None)),
            C.pointer(Assembly(ASSEMBLY, None, 0, 3, 0)), None,
            C.pointer(ViewportState(VIEWPORT, None, 0, 1, None, 1, None)),
            C.pointer(Raster(RASTER, None, 0, 0, 0, 0, 0, 0, 0, 0.0, 0.0, 0.0, 1.0)),
            C.pointer(Multisample(MULTISAMPLE, None, 0, 1, 0, 0.0, None, 0, 0)), None,
            C.pointer(Blend(BLEND, None, 0, 0, 0, OUTPUTS, blends, (f32 * 4)())),
            C.pointer(Dynamic(DYNAMIC, None, 0, 2, dynamic)),
            self.layout, self.render_pass, 0, None, -1)
        pipeline = Handle()
        _check(self.vk.vkCreateGraphicsPipelines(self.device, None, 1, C.byref(info), None,
                                                 C.byref(pipeline)), "vkCreateGraphicsPipelines")
        which = PipelineKHR(PIPELINE_INFO_KHR, None, pipeline)
        count = u32(0)
        _check(self.executables(self.device, C.addressof(which), C.byref(count), None),
               "vkGetPipelineExecutablePropertiesKHR")
        props = (ExecutableProperties * count.value)(
            *[ExecutableProperties(EXECUTABLE_PROPERTIES) for _ in range(count.value)])
        _check(self.executables(self.device, C.addressof(which), C.byref(count),
                                C.addressof(props)), "vkGetPipelineExecutablePropertiesKHR")
        index = next((i for i, e in enumerate(props) if e.stages & FRAGMENT_BIT), None)
        if index is None:
            raise VulkanError("the pipeline has no fragment executable")
        return self._statistics(pipeline, index)

    def _statistics(self, pipeline: Handle, index: int) -> dict[str, float]:
        which = ExecutableInfo(EXECUTABLE_INFO, None, pipeline, index)
        count = u32(0)
        _check(self.statistics(self.device, C.addressof(which), C.byref(count), None),
               "vkGetPipelineExecutableStatisticsKHR")
        stats = (Statistic * count.value)(*[Statistic(STATISTIC) for _ in range(count.value)])
        _check(self.statistics(self.device, C.addressof(which), C.byref(count),
                               C.addressof(stats)), "vkGetPipelineExecutableStatisticsKHR")
        kinds = {0: "b32", 1: "i64", 2: "u64", 3: "f64"}
        return {s.name.decode(): getattr(s.value, kinds[s.format]) for s in stats}


def main() -> int:
    """The child process: JSON request on stdin, JSON answer on stdout."""
    request = json.load(sys.stdin)
    try:
        client = Client()
        vertex = bytes.fromhex(request["vertex"])
        stats = [client.fragment_stats(vertex, bytes.fromhex(f)) for f in request["fragments"]]
    except (OSError, VulkanError) as exc:
        json.dump({"error": str(exc)}, sys.stdout)
        return 0
    json.dump({"device": client.name, "stats": stats}, sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
