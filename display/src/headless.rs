//! Headless rendering: the window's pipeline drawn into an offscreen target and read back to an image.
use crate::{DisplayError, Frame, Presenter, Result, SharedDevice, instance, map_read};

/// Renders `img` (RGBA8) through the display pipeline into an offscreen target of `size` and reads it
/// back: exactly what the window shows at that size.
pub fn render_headless(img: &image::RgbaImage, size: (u32, u32)) -> Result<image::RgbImage> {
    let inst = instance();
    let adapter = pollster::block_on(inst.request_adapter(&wgpu::RequestAdapterOptions::default()))
        .map_err(|e| DisplayError::NoAdapter(e.to_string()))?;
    let (device, queue) =
        pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default()))
            .map_err(|e| DisplayError::Gpu(e.to_string()))?;
    let dev = SharedDevice {
        instance: inst,
        adapter,
        device,
        queue,
    };
    render_headless_frame(
        &dev,
        Frame::Rgba(img.as_raw().clone()),
        img.dimensions(),
        size,
    )
}

/// [`render_headless`] of a [`Frame`] of `img_size` on a given device (a [`Frame::Buffer`] must be
/// on it): the window's pipeline, drawn into an offscreen target of `size` and read back.
pub fn render_headless_frame(
    dev: &SharedDevice,
    frame: Frame,
    img_size: (u32, u32),
    size: (u32, u32),
) -> Result<image::RgbImage> {
    let (device, queue) = (&dev.device, &dev.queue);
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let mut p = Presenter::new(device.clone(), queue.clone(), format, img_size);
    match frame {
        Frame::Rgba(rgba) => p.upload(&rgba, img_size),
        Frame::Buffer(b) => p.upload_buffer(&b, img_size),
    }
    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("colcos headless target"),
        size: wgpu::Extent3d {
            width: size.0,
            height: size.1,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let row = (4 * size.0).next_multiple_of(256);
    let buf = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: row as u64 * size.1 as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    p.draw(&mut enc, &target.create_view(&Default::default()), size);
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture: &target,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buf,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row),
                rows_per_image: Some(size.1),
            },
        },
        wgpu::Extent3d {
            width: size.0,
            height: size.1,
            depth_or_array_layers: 1,
        },
    );
    queue.submit([enc.finish()]);
    map_read(device, &buf)?;
    let mut out = image::RgbImage::new(size.0, size.1);
    {
        let view = buf
            .get_mapped_range(..)
            .map_err(|e| DisplayError::Gpu(format!("{e:?}")))?;
        for y in 0..size.1 as usize {
            let src = &view[y * row as usize..][..4 * size.0 as usize];
            let dst = &mut out.as_mut()[y * 3 * size.0 as usize..][..3 * size.0 as usize];
            for (d, s) in dst.chunks_exact_mut(3).zip(src.chunks_exact(4)) {
                d.copy_from_slice(&s[..3]);
            }
        }
    }
    buf.unmap();
    Ok(out)
}
