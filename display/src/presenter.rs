//! The image texture and the render pipeline that draws it, 1:1 or scaled to fit, onto a window's
//! surface or an offscreen target.

const SHADER: &str = r#"
struct V {
    img: vec2<f32>,
    off: vec2<f32>,
    scale: vec2<f32>,
    _pad: vec2<f32>,
};
@group(0) @binding(0) var tex: texture_2d<f32>;
@group(0) @binding(1) var<uniform> v: V;

@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32((i << 1u) & 2u);
    let y = f32(i & 2u);
    return vec4<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0, 0.0, 1.0);
}

@fragment
fn fs(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let q = (p.xy - v.off) * v.scale;
    if (q.x < 0.0 || q.y < 0.0 || q.x >= v.img.x || q.y >= v.img.y) {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    let c = textureLoad(tex, vec2<i32>(floor(q)), 0);
    return vec4<f32>(c.rgb, 1.0);
}
"#;

/// The image texture and the pipeline that draws it onto a target of some format and size.
pub struct Presenter {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    texture: wgpu::Texture,
    uniform: wgpu::Buffer,
    bind: wgpu::BindGroup,
    size: (u32, u32),
}

impl Presenter {
    pub fn new(
        device: wgpu::Device,
        queue: wgpu::Queue,
        target: wgpu::TextureFormat,
        size: (u32, u32),
    ) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("colcos display"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: None,
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("colcos display"),
            layout: Some(&pl),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: target,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: None,
            size: 32,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let (texture, bind) = Self::make_texture(&device, &layout, &uniform, size);
        Presenter {
            device,
            queue,
            pipeline,
            layout,
            texture,
            uniform,
            bind,
            size,
        }
    }

    fn make_texture(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        uniform: &wgpu::Buffer,
        size: (u32, u32),
    ) -> (wgpu::Texture, wgpu::BindGroup) {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("colcos screen image"),
            size: wgpu::Extent3d {
                width: size.0.max(1),
                height: size.1.max(1),
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8Unorm,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: uniform.as_entire_binding(),
                },
            ],
        });
        (texture, bind)
    }

    /// Replaces the texture when `size` changes; false for an empty image (nothing to copy).
    fn fit_texture(&mut self, size: (u32, u32)) -> bool {
        if size != self.size {
            let (t, b) = Self::make_texture(&self.device, &self.layout, &self.uniform, size);
            self.texture = t;
            self.bind = b;
            self.size = size;
        }
        size.0 != 0 && size.1 != 0
    }

    /// Uploads an RGBA8 image of `size` (replacing the texture when the size changes).
    pub fn upload(&mut self, rgba: &[u8], size: (u32, u32)) {
        if !self.fit_texture(size) {
            return;
        }
        self.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            rgba,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * size.0),
                rows_per_image: Some(size.1),
            },
            wgpu::Extent3d {
                width: size.0,
                height: size.1,
                depth_or_array_layers: 1,
            },
        );
    }

    /// Copies an image of `size` from `buffer` (packed RGBA8, on this presenter's device) into the
    /// texture, on the GPU.
    pub fn upload_buffer(&mut self, buffer: &wgpu::Buffer, size: (u32, u32)) {
        if !self.fit_texture(size) {
            return;
        }
        let row = 4 * size.0;
        let mut enc = self.device.create_command_encoder(&Default::default());
        let copy = |enc: &mut wgpu::CommandEncoder, y: u32, rows: u32| {
            enc.copy_buffer_to_texture(
                wgpu::TexelCopyBufferInfo {
                    buffer,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: y as u64 * row as u64,
                        bytes_per_row: (rows > 1).then_some(row),
                        rows_per_image: None,
                    },
                },
                wgpu::TexelCopyTextureInfo {
                    texture: &self.texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y, z: 0 },
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::Extent3d {
                    width: size.0,
                    height: rows,
                    depth_or_array_layers: 1,
                },
            );
        };
        if row.is_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) {
            copy(&mut enc, 0, size.1);
        } else {
            // Rows not 256-byte aligned: one copy per row (a single row needs no alignment).
            for y in 0..size.1 {
                copy(&mut enc, y, 1);
            }
        }
        self.queue.submit([enc.finish()]);
    }

    /// Draws the image onto `target` (`target_size` pixels): 1:1 when the sizes agree, else scaled to fit.
    pub fn draw(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        target_size: (u32, u32),
    ) {
        let (w, h) = (self.size.0.max(1) as f32, self.size.1.max(1) as f32);
        let (tw, th) = (target_size.0 as f32, target_size.1 as f32);
        let s = (tw / w).min(th / h);
        let s = if (s - 1.0).abs() < 1e-6 { 1.0 } else { s };
        let off = [((tw - w * s) * 0.5).floor(), ((th - h * s) * 0.5).floor()];
        let data: [f32; 8] = [w, h, off[0], off[1], 1.0 / s, 1.0 / s, 0.0, 0.0];
        self.queue
            .write_buffer(&self.uniform, 0, bytemuck::cast_slice(&data));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("colcos display"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind, &[]);
        pass.draw(0..3, 0..1);
    }
}
