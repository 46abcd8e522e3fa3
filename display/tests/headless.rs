//! A frame handed over as a GPU buffer (what the window gets when the field backend's GPU composes
//! the screen) shows the same pixels as the same image handed over as bytes, for row sizes that are
//! and are not multiples of wgpu's 256-byte copy alignment. Needs a GPU adapter (lavapipe in CI),
//! not a display.
use colcos_display::{Frame, SharedDevice, render_headless, render_headless_frame};

fn device() -> Option<SharedDevice> {
    let instance =
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter =
        match pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
        {
            Ok(a) => a,
            Err(e) => {
                if std::env::var("COLCOS_REQUIRE_GPU").is_ok_and(|v| v == "1") {
                    panic!("COLCOS_REQUIRE_GPU=1 but no adapter: {e}");
                }
                eprintln!("skipping: no GPU adapter ({e})");
                return None;
            }
        };
    let (device, queue) =
        pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor::default())).unwrap();
    Some(SharedDevice {
        instance,
        adapter,
        device,
        queue,
    })
}

fn pattern(w: u32, h: u32) -> image::RgbaImage {
    image::RgbaImage::from_fn(w, h, |x, y| {
        image::Rgba([
            (x * 7 % 256) as u8,
            (y * 13 % 256) as u8,
            ((x ^ y) & 0xff) as u8,
            255,
        ])
    })
}

#[test]
fn buffer_frames_show_the_same_pixels() {
    let Some(dev) = device() else { return };
    for (w, h) in [(320, 180), (317, 181), (1, 1)] {
        let img = pattern(w, h);
        let buffer = dev.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame"),
            size: (w * h * 4) as u64,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_SRC
                | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        dev.queue.write_buffer(&buffer, 0, img.as_raw());
        for target in [(w, h), (2 * w + 3, 2 * h + 1)] {
            let from_buffer =
                render_headless_frame(&dev, Frame::Buffer(buffer.clone()), (w, h), target).unwrap();
            let from_bytes = render_headless(&img, target).unwrap();
            assert!(
                from_buffer == from_bytes,
                "{w}x{h} shown at {target:?}: the buffer frame differs from the byte frame"
            );
        }
    }
}
