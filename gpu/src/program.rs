//! A WGSL compute shader compiled into pipelines that all bind one layout of buffers, the bind groups
//! of whole buffers they take, and the structs shared with the shaders ([`shader_struct`]).

/// A buffer binding of a compute shader: its type, and whether it takes a dynamic offset.
pub(crate) type Binding = (wgpu::BufferBindingType, bool);

/// A read-only storage buffer.
pub(crate) const READ: Binding = (wgpu::BufferBindingType::Storage { read_only: true }, false);
/// A read-write storage buffer.
pub(crate) const WRITE: Binding = (wgpu::BufferBindingType::Storage { read_only: false }, false);
/// A uniform buffer.
pub(crate) const UNIFORM: Binding = (wgpu::BufferBindingType::Uniform, false);

/// A compiled WGSL module and the bind group layout its entry points share: binding `i` is the
/// buffer `bindings[i]` given to [`ComputeProgram::new`].
pub(crate) struct ComputeProgram {
    module: wgpu::ShaderModule,
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
}

impl ComputeProgram {
    /// Compiles `source`; `name` labels the module and its layouts in wgpu's messages.
    pub(crate) fn new(
        device: &wgpu::Device,
        name: &str,
        source: String,
        bindings: &[Binding],
    ) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(&format!("colcos {name}.wgsl")),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let entries: Vec<_> = (0u32..)
            .zip(bindings)
            .map(|(binding, &(ty, dynamic))| wgpu::BindGroupLayoutEntry {
                binding,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty,
                    has_dynamic_offset: dynamic,
                    min_binding_size: None,
                },
                count: None,
            })
            .collect();
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(&format!("colcos {name} layout")),
            entries: &entries,
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(&format!("colcos {name} pipeline layout")),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        ComputeProgram {
            module,
            layout,
            pipeline_layout,
        }
    }

    /// The pipeline of entry point `entry`.
    pub(crate) fn pipeline(&self, device: &wgpu::Device, entry: &str) -> wgpu::ComputePipeline {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(&self.pipeline_layout),
            module: &self.module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        })
    }

    /// The bind group layout, for the bind groups of the pipelines made.
    pub(crate) fn into_layout(self) -> wgpu::BindGroupLayout {
        self.layout
    }
}

/// A bind group of `layout` that binds whole buffers, `buffers[i]` at binding `i`.
pub(crate) fn bind_buffers(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    label: &str,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let entries: Vec<_> = (0u32..)
        .zip(buffers)
        .map(|(binding, buffer)| wgpu::BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// A struct the shaders read, declared once: the Rust struct (`#[repr(C)]`, plain old data) and,
/// as `WGSL`, the shader's declaration of it (named `$wgsl`), which the shader's source takes in
/// place of a marker, so that the two layouts cannot drift apart. Fields are `u32`, `i32`, `f32`
/// or arrays of them, 4-byte aligned in both languages.
macro_rules! shader_struct {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident as $wgsl:ident {
            $($(#[$field_meta:meta])* $field_vis:vis $field:ident: $ty:tt,)*
        }
    ) => {
        $(#[$meta])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
        $vis struct $name {
            $($(#[$field_meta])* $field_vis $field: $ty,)*
        }

        impl $name {
            /// The shader's declaration of this struct.
            pub(crate) const WGSL: &str = concat!(
                "struct ",
                stringify!($wgsl),
                " {\n",
                $("    ", stringify!($field), ": ", $crate::program::wgsl_type!($ty), ",\n",)*
                "};\n"
            );
        }
    };
}
pub(crate) use shader_struct;

/// The WGSL spelling of a [`shader_struct`] field's type.
macro_rules! wgsl_type {
    ([$t:ident; $n:literal]) => {
        concat!("array<", stringify!($t), ", ", stringify!($n), ">")
    };
    ($t:ident) => {
        stringify!($t)
    };
}
pub(crate) use wgsl_type;
