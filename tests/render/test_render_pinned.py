"""The presets clean, mild, realsense and hard, which use none of the realism knobs (printed faces, multi-hue
solids, contacts, small tables), render bit-identically whatever knobs exist beside them: colour, depth, face
mask and ground truth of fixed scenes are pinned by their sha256."""

import hashlib
import json

import pytest

from lv3d.render import render_scene

# (preset, class, seed, width, height, sha256 of colour bytes, of depth bytes, of the face mask's bytes,
#  of the truth as sorted JSON)
PINNED = [
    ("clean", "cube", 0, 320, 240,
     "fa4ca24bc3fc372609b1e124062322aec0ff2bc3edaf59ab4f5585f1ac3d038d",
     "7c04d125f4724fc50113ec4f5ae5900b79d88a6bbdc39ea72e9bc8482695c16e",
     "07381d6abb4eae535d5f440b8ec3f3739fd2bedf93e64556545c0321c809bb46",
     "94e742352a9ba8ea2611d41a0e722e5a9c8689abcb5a37b5f36b2a413fc57d41"),
    ("clean", "hexagonal_prism", 1, 160, 120,
     "bec3e32e3365efda8058697ec0b9ec06bdbb71cdc8ecafe8699e758e49ffecb3",
     "9c79cbd6563bb194970debd0cfceecf54523f4ad7006e34a749aa035e897016b",
     "2737abc72e3744d3ddefba67c2b3bb9688eb008207e1886894b26c1f4fb8e081",
     "b759ccae317cc5837c76be073c5175e57e998744782ef3fa13e1ce1d498c6b46"),
    ("clean", "tetrahedron", 2, 160, 120,
     "d9c644bb1aae5bcabf7f9ec899e3a7a26c825377bc0a10eb0c3e34c254bb39c3",
     "a927c140b01e150b736f002e0df4b1a2995f28157f20e290d01917cafb4fcf67",
     "105a698e644797b8e0160e415aac2d677bf72c24323487ae7faf5333ab012f0c",
     "955e9f4f020e52482c7161b8677eda82f4002282967be093b39dca59314cb528"),
    ("clean", "cuboid", 3, 640, 480,
     "5a9f17ec1de3d9b733d96dcb9b45fb28fed397d9106e3624c306655e29e893aa",
     "fcf7e0a64e32bcb2c23df623eac53ab2adc34187a412f4040a21eda5f990a5ab",
     "6ccb6925bdd800629ca7034468356d1802e3188814d659bd4791cda16c4bf8ca",
     "d68210c91274eb231de4477aa4c2a6b5c48ba34ff1717878aba7fc6775110978"),
    ("clean", "square_pyramid", 4, 160, 120,
     "6d9ab3ae129cc947fb2bf642252471a5570d8e72422b1bbbd02091837b6eb362",
     "6136c623c5cdf97e9dea5ac5682354bc996238256418bb6ece93663b0bdff738",
     "b29331b4aeb0ef0665403bd263936d16a7c9f0c78215fdee523df8dd449da7fd",
     "42c438c1cbe89f76fdf7f266f889a48d6e927b8e3d05bf72cd7f5ea980672d2c"),
    ("mild", "cube", 0, 320, 240,
     "8ad354f3851a3ed4034f52bc14e69c2f14b522bfe52971f62c5baf9226075db6",
     "15c7e0e1efb51d4c762014e94f5280c89060bba07b834cf0391faaf59aef45e9",
     "07381d6abb4eae535d5f440b8ec3f3739fd2bedf93e64556545c0321c809bb46",
     "fac6eac1f5de996515a55e4e972d9968872b60d155cfdf411f2f9a45a5e401b5"),
    ("mild", "hexagonal_prism", 1, 160, 120,
     "f7c8401e1434440ca00faa01257f3cd4d61f7994068b94a981ce89764d969883",
     "be54b2986fdb803799edb3f66ff97ea1d0a183d1f020647b2d442c7ee00647cd",
     "2737abc72e3744d3ddefba67c2b3bb9688eb008207e1886894b26c1f4fb8e081",
     "a51dd2f9075b624c3cc552f9a9543b291f9870d26b1db406658383b80525ba9d"),
    ("mild", "tetrahedron", 2, 160, 120,
     "5d3514423fd0316c7c4480c6daf30b4ef10f4f3bccae87752d2f6203934a1da2",
     "096d4abc946e04f41e96a3faea71ac47cd025ea977963da46c3a03dd48986cd9",
     "105a698e644797b8e0160e415aac2d677bf72c24323487ae7faf5333ab012f0c",
     "606721d7b538ec30f20f94c7b328858b5a63e2f4b79325b868763a70b62346cb"),
    ("mild", "cuboid", 3, 640, 480,
     "0a94867840e2b0b82c1bdadd82ced2499481ba52e7abe371f4d44fa52448a24d",
     "8435114e39cb55e0d8eae2d762b60bf34884fc3cff932468bf1ae1af379d3ce6",
     "6ccb6925bdd800629ca7034468356d1802e3188814d659bd4791cda16c4bf8ca",
     "5b83a3628d0c0d9d8010506daa30e0551b9363a2f63620b7fcdde912995e815a"),
    ("mild", "square_pyramid", 4, 160, 120,
     "ba5c6b9d94396e42d27705c61566c12396811364cdbec091b43982ded4c72f80",
     "35ccbb43f18f18b2b3a173889e8822e421df6bb3f3936aa4e476199c96fb9d6d",
     "b29331b4aeb0ef0665403bd263936d16a7c9f0c78215fdee523df8dd449da7fd",
     "b8467992993c43e913fb06afbb0ca65b626c4f06524c4f54bdc1fa91db7a0e1c"),
    ("realsense", "cube", 0, 320, 240,
     "400f4f5cf851253dadb96feddee4244b149b2b531eef2f287172e404caebeb75",
     "3badbe1f90e22794fe884ed7faf00cef9d2336415b37de182ecb6943cb1c8a70",
     "07381d6abb4eae535d5f440b8ec3f3739fd2bedf93e64556545c0321c809bb46",
     "0262d7b0e4eda4523989f0ca5a07fa45a0b20ead5891ece00f9290dc28f45b2c"),
    ("realsense", "hexagonal_prism", 1, 160, 120,
     "8457b542d51e80f49e42963ce3de1777461086fee3cc721dfca8222cd6c45973",
     "4fe67dc013fd69a22a83c0fe130e6b562f070915c8cf32376f426c0c2d7dcb4a",
     "2737abc72e3744d3ddefba67c2b3bb9688eb008207e1886894b26c1f4fb8e081",
     "a0ce062c856c8bb1777a2002cc7707cbd505423473e319b0ff60f066b5c9ffa4"),
    ("realsense", "tetrahedron", 2, 160, 120,
     "a1a11bd673b912a8cc8b9c6d11a8a314341b35f06b71a637a1d4a541a42adcb1",
     "db8a1ae9e64e9a83ec4be58d5d215817612e0dd15f00c958e38f88697fb59e89",
     "7f462c284e045e9df7ad87df04841460c5293c3de77d993a6b6d4d13172aa107",
     "2e25fb2047827aec2baa634fd42eaa14d2573521555131be870637c3e7b23ce1"),
    ("realsense", "cuboid", 3, 640, 480,
     "df906ba97aa6662b050bd4673c8e6a3a3e597324dc661b47186db46068cd2d04",
     "95e5329d38b033111503d871b5ab458df1adc95d36a2589e7275c49704d9f632",
     "6ccb6925bdd800629ca7034468356d1802e3188814d659bd4791cda16c4bf8ca",
     "4e9ff20d50633ce5a3fc381fb89973eb8944a300acddaf13d5de84775e847ed1"),
    ("realsense", "square_pyramid", 4, 160, 120,
     "d9e506a4149abe69cd862ecf2470b3ac0321824fc8f2abd5bbd5f591ea05c45b",
     "cdf5b46634a9e0b0bc7209091de24526eb0d0b40909b677f9e90365d7b80f00d",
     "b29331b4aeb0ef0665403bd263936d16a7c9f0c78215fdee523df8dd449da7fd",
     "e27c111e959292bc2f49d9b496b0211a44acfab7be6f4c1c3c845b35aa9f8915"),
    ("hard", "cube", 0, 320, 240,
     "2e726b94478b8da3ba431ffe13042b00bf6a672e144fe18ee809cbc8556e3c20",
     "1759ed3c44e4b9b8b95a2b6b47c77b1ec1c20308c7d5376cfede971bb539149e",
     "07381d6abb4eae535d5f440b8ec3f3739fd2bedf93e64556545c0321c809bb46",
     "5629c6b9f6bcdee885731b36b9b01ab7f7e07eab740d95d5e5a361149c7e23f4"),
    ("hard", "hexagonal_prism", 1, 160, 120,
     "3a30445005b5c82879549953dd2a075c6a782ba4854184cd385f089b479a78fa",
     "86dcee0ca208c355d9797a304cd356f8d72b40c5d013b114f2c356a3fef41283",
     "d7ed3d1d58285065d86c437ff68ef191dbb9b33ae7b2463c4be6425c71868046",
     "b34ae0e1be2bf68cab1f6628883fddaff40de86fe8e73bf987f4209aeb51d7f7"),
    ("hard", "tetrahedron", 2, 160, 120,
     "81886908e5374a2ee2caefc70897bab4e38f2960d8e7b5b30909d7be52c842f8",
     "363446607eb2e8daf8c73fcbce85f2148c90b3200193c27ba29c439f7a70f720",
     "105a698e644797b8e0160e415aac2d677bf72c24323487ae7faf5333ab012f0c",
     "8e3c125bb18c278f449ac1d5d2d3ed70e27801775e73cc4a2e9f0544f22bd2a9"),
    ("hard", "cuboid", 3, 640, 480,
     "706c927515e96b8b929ee97ba7d7229b29dca34446f9a312f30e97a944335655",
     "e5878e235c9d0142585b9b1745d7dba6ae675a69209c14a64e78656231f72894",
     "6ccb6925bdd800629ca7034468356d1802e3188814d659bd4791cda16c4bf8ca",
     "685082d61ea1da3c67611f441b12cb99e6ed23b97baeccf2cb1212bab9f6cec4"),
    ("hard", "square_pyramid", 4, 160, 120,
     "901f68fe01e620b0e427e17c1bf5a32996c0972fce51f3d8b06f5e2eebcc2176",
     "909aee80e42e71eecd3e5b8af4e26337d0aa953c591a6ce114d8bb6e57a8d070",
     "52d3bef382bc4665373a10dd2bb17e634674ceaceca18da91e8b41a41f6edb35",
     "1c050bc64e1f7635f29ffee60c6deb1378eaa6e8b206d592383302c4ce3dd901"),
]

# truth keys these presets carry besides the pinned ones: no contacts, and the target stands on the table
_ADDED_TRUTH_KEYS = ("contacts", "table_plane")


def _sha(b: bytes) -> str:
    return hashlib.sha256(b).hexdigest()


@pytest.mark.parametrize("preset, cls, seed, width, height, color, depth, faces, truth", PINNED,
                         ids=[f"{p[0]}-{p[1]}-{p[3]}" for p in PINNED])
def test_presets_without_realism_knobs_render_bit_identically(preset, cls, seed, width, height, color, depth, faces, truth):
    frame, mask = render_scene(cls, seed, preset, width, height)
    assert _sha(frame.color.tobytes()) == color
    assert _sha(frame.depth.tobytes()) == depth
    assert _sha(mask.tobytes()) == faces
    t = dict(frame.meta["truth"])
    assert t["contacts"] == [] and t["table_plane"] == t["support_plane"]
    for key in _ADDED_TRUTH_KEYS:
        t.pop(key)
    assert _sha(json.dumps(t, sort_keys=True).encode()) == truth
