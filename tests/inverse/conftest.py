import pytest

torch = pytest.importorskip("torch")
torch.set_num_threads(1)


@pytest.fixture(scope="session")
def tiny_data():
    from satmd.inverse import make_dataset

    return make_dataset("paper", samples_per_pair=6, val_fraction=0.2, seed=1)


@pytest.fixture(scope="session")
def tiny_physics(tiny_data):
    from satmd.inverse import InverseModel

    model = InverseModel("physics", epochs=4, warm_start_epochs=2, n_members=3, batch_size=64, seed=3,
                         verbose=False, mc_samples=8)
    return model.fit(tiny_data)
