//! The GL state a host may rely on, queried before and after umbra's calls and compared.

use umbra_gl::glow::{self, HasContext};

/// The GL state a host cares about, queried independently of umbra's own save/restore.
pub(crate) fn query_state(gl: &glow::Context) -> Vec<(String, Vec<i64>)> {
    let mut out = Vec::new();
    // SAFETY: glGet* queries of core state on the current context.
    unsafe {
        let ints = [
            ("BLEND", glow::BLEND, 1),
            ("BLEND_SRC_RGB", glow::BLEND_SRC_RGB, 1),
            ("BLEND_DST_RGB", glow::BLEND_DST_RGB, 1),
            ("BLEND_SRC_ALPHA", glow::BLEND_SRC_ALPHA, 1),
            ("BLEND_DST_ALPHA", glow::BLEND_DST_ALPHA, 1),
            ("BLEND_EQUATION_RGB", glow::BLEND_EQUATION_RGB, 1),
            ("BLEND_EQUATION_ALPHA", glow::BLEND_EQUATION_ALPHA, 1),
            ("DEPTH_TEST", glow::DEPTH_TEST, 1),
            ("DEPTH_FUNC", glow::DEPTH_FUNC, 1),
            ("DEPTH_WRITEMASK", glow::DEPTH_WRITEMASK, 1),
            ("DEPTH_CLAMP", glow::DEPTH_CLAMP, 1),
            ("STENCIL_TEST", glow::STENCIL_TEST, 1),
            ("STENCIL_FUNC", glow::STENCIL_FUNC, 1),
            ("STENCIL_REF", glow::STENCIL_REF, 1),
            ("STENCIL_VALUE_MASK", glow::STENCIL_VALUE_MASK, 1),
            ("STENCIL_WRITEMASK", glow::STENCIL_WRITEMASK, 1),
            ("STENCIL_FAIL", glow::STENCIL_FAIL, 1),
            ("STENCIL_PASS_DEPTH_FAIL", glow::STENCIL_PASS_DEPTH_FAIL, 1),
            ("STENCIL_PASS_DEPTH_PASS", glow::STENCIL_PASS_DEPTH_PASS, 1),
            ("STENCIL_BACK_FUNC", glow::STENCIL_BACK_FUNC, 1),
            ("STENCIL_BACK_REF", glow::STENCIL_BACK_REF, 1),
            ("STENCIL_BACK_VALUE_MASK", glow::STENCIL_BACK_VALUE_MASK, 1),
            ("STENCIL_BACK_WRITEMASK", glow::STENCIL_BACK_WRITEMASK, 1),
            ("STENCIL_BACK_FAIL", glow::STENCIL_BACK_FAIL, 1),
            ("STENCIL_BACK_PASS_DEPTH_FAIL", glow::STENCIL_BACK_PASS_DEPTH_FAIL, 1),
            ("STENCIL_BACK_PASS_DEPTH_PASS", glow::STENCIL_BACK_PASS_DEPTH_PASS, 1),
            ("CULL_FACE", glow::CULL_FACE, 1),
            ("CULL_FACE_MODE", glow::CULL_FACE_MODE, 1),
            ("FRONT_FACE", glow::FRONT_FACE, 1),
            ("CLIP_ORIGIN", glow::CLIP_ORIGIN, 1),
            ("CLIP_DEPTH_MODE", glow::CLIP_DEPTH_MODE, 1),
            ("CURRENT_PROGRAM", glow::CURRENT_PROGRAM, 1),
            ("VERTEX_ARRAY_BINDING", glow::VERTEX_ARRAY_BINDING, 1),
            ("DRAW_FRAMEBUFFER_BINDING", glow::DRAW_FRAMEBUFFER_BINDING, 1),
            ("READ_FRAMEBUFFER_BINDING", glow::READ_FRAMEBUFFER_BINDING, 1),
            ("VIEWPORT", glow::VIEWPORT, 4),
            ("COLOR_WRITEMASK", glow::COLOR_WRITEMASK, 4),
            ("SCISSOR_TEST", glow::SCISSOR_TEST, 1),
            ("SCISSOR_BOX", glow::SCISSOR_BOX, 4),
            ("RASTERIZER_DISCARD", glow::RASTERIZER_DISCARD, 1),
            ("POLYGON_OFFSET_FILL", glow::POLYGON_OFFSET_FILL, 1),
            ("PATCH_VERTICES", glow::PATCH_VERTICES, 1),
            ("ACTIVE_TEXTURE", glow::ACTIVE_TEXTURE, 1),
            ("ARRAY_BUFFER_BINDING", glow::ARRAY_BUFFER_BINDING, 1),
            ("DRAW_INDIRECT_BUFFER_BINDING", glow::DRAW_INDIRECT_BUFFER_BINDING, 1),
            ("DISPATCH_INDIRECT_BUFFER_BINDING", glow::DISPATCH_INDIRECT_BUFFER_BINDING, 1),
            ("COPY_READ_BUFFER_BINDING", glow::COPY_READ_BUFFER_BINDING, 1),
            ("SHADER_STORAGE_BUFFER_BINDING", glow::SHADER_STORAGE_BUFFER_BINDING, 1),
            ("UNIFORM_BUFFER_BINDING", glow::UNIFORM_BUFFER_BINDING, 1),
            ("DRAW_BUFFER0", glow::DRAW_BUFFER0, 1),
            ("DRAW_BUFFER3", glow::DRAW_BUFFER3, 1),
        ];
        for (name, pname, n) in ints {
            let mut v = vec![0i32; n];
            gl.get_parameter_i32_slice(pname, &mut v);
            out.push((name.to_string(), v.into_iter().map(i64::from).collect()));
        }
        let mut range = [0.0f32; 2];
        gl.get_parameter_f32_slice(glow::DEPTH_RANGE, &mut range);
        out.push(("DEPTH_RANGE".into(), range.iter().map(|f| i64::from(f.to_bits())).collect()));
        let offset = [glow::POLYGON_OFFSET_FACTOR, glow::POLYGON_OFFSET_UNITS].map(|p| gl.get_parameter_f32(p));
        out.push(("POLYGON_OFFSET".into(), offset.iter().map(|f| i64::from(f.to_bits())).collect()));
        for i in 0..8 {
            out.push((
                format!("SHADER_STORAGE_BUFFER_BINDING[{i}]"),
                vec![
                    i64::from(gl.get_parameter_indexed_i32(glow::SHADER_STORAGE_BUFFER_BINDING, i)),
                    gl.get_parameter_indexed_i64(glow::SHADER_STORAGE_BUFFER_START, i),
                    gl.get_parameter_indexed_i64(glow::SHADER_STORAGE_BUFFER_SIZE, i),
                ],
            ));
        }
        out.push((
            "UNIFORM_BUFFER_BINDING[14]".into(),
            vec![
                i64::from(gl.get_parameter_indexed_i32(glow::UNIFORM_BUFFER_BINDING, 14)),
                gl.get_parameter_indexed_i64(glow::UNIFORM_BUFFER_START, 14),
                gl.get_parameter_indexed_i64(glow::UNIFORM_BUFFER_SIZE, 14),
            ],
        ));
        for i in 0..8 {
            out.push((format!("CLIP_DISTANCE{i}"), vec![i64::from(gl.is_enabled(glow::CLIP_DISTANCE0 + i))]));
        }
        // Unit 0's textures (the shadow map's unit), queried through the active unit.
        let active = gl.get_parameter_i32(glow::ACTIVE_TEXTURE) as u32;
        gl.active_texture(glow::TEXTURE0);
        for (name, pname) in [
            ("TEXTURE_BINDING_2D[0]", glow::TEXTURE_BINDING_2D),
            ("TEXTURE_BINDING_CUBE_MAP[0]", glow::TEXTURE_BINDING_CUBE_MAP),
        ] {
            out.push((name.into(), vec![i64::from(gl.get_parameter_i32(pname))]));
        }
        gl.active_texture(active);
    }
    out
}

pub(crate) fn assert_same_state(before: &[(String, Vec<i64>)], after: &[(String, Vec<i64>)], what: &str) {
    let changed: Vec<String> = before
        .iter()
        .zip(after)
        .filter(|(b, a)| b != a)
        .map(|(b, a)| format!("{}: {:?} -> {:?}", b.0, b.1, a.1))
        .collect();
    assert!(changed.is_empty(), "{what} changed the host's GL state: {changed:#?}");
}
